"""Figures of skills: the graph (primitives, transitions, conditions) and execution traces.

matplotlib with the Agg backend (no display needed). The graph is laid out left to right
in breadth-first order from the start node; transitions are labelled with their conditions,
every node's error exit leads (dashed, red) to the recovery node below, and the success
condition leads to the terminal node on the right.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import FancyBboxPatch  # noqa: E402

from teachfit.execution.engine import ExecutionResult  # noqa: E402
from teachfit.skills.graph import Skill  # noqa: E402
from teachfit.viz.output import save_figure


def _order(skill: Skill) -> list[str]:
    order, frontier = [skill.start], [skill.start]
    while frontier:
        here = frontier.pop(0)
        for tr in skill.transitions:
            if tr.source == here and tr.target not in order:
                order.append(tr.target)
                frontier.append(tr.target)
    return order


#: distance between node centres, and a node box's half width (data units)
_STEP, _HALF = 2.0, 0.42


def _box(
    ax: plt.Axes, xy: tuple[float, float], title: str, body: str, color: str, half: float = _HALF
) -> None:
    x, y = xy
    ax.add_patch(
        FancyBboxPatch(
            (x - half, y - 0.32),
            2 * half,
            0.64,
            boxstyle="round,pad=0.02",
            fc=color,
            ec="k",
            lw=1.2,
        )
    )
    ax.text(x, y + 0.2, title, ha="center", va="center", fontsize=10, weight="bold")
    ax.text(x, y - 0.05, textwrap.fill(body, 26), ha="center", va="center", fontsize=6.5)


def _arrow(
    ax: plt.Axes,
    a: tuple[float, float],
    b: tuple[float, float],
    label: str,
    color: str = "k",
    style: str = "-",
    rad: float = 0.0,
    dy: float = 0.0,
    frac: float = 0.5,
) -> None:
    ax.annotate(
        "",
        xy=b,
        xytext=a,
        arrowprops=dict(
            arrowstyle="-|>",
            color=color,
            ls=style,
            lw=1.2,
            connectionstyle=f"arc3,rad={rad}",
            shrinkA=2,
            shrinkB=2,
        ),
    )
    mx, my = a[0] + frac * (b[0] - a[0]), a[1] + frac * (b[1] - a[1]) + dy
    ax.text(
        mx,
        my,
        textwrap.fill(label, 22),
        ha="center",
        va="bottom",
        fontsize=6.5,
        color=color,
        bbox=dict(fc="white", ec="none", alpha=0.8, pad=0.5),
    )


def plot_skill_graph(skill: Skill, path: str | Path) -> Path:
    """Draw ``skill``'s graph to ``path`` (png/pdf/svg by suffix)."""
    path = Path(path)
    order = _order(skill)
    pos = {name: (_STEP * (i + 1), 0.0) for i, name in enumerate(order)}
    n = len(order)
    fig, ax = plt.subplots(figsize=(1.6 * _STEP * (n + 1.4), 5.4), constrained_layout=True)
    end = _draw_entry_and_exit(ax, skill, pos, n)
    for node in skill.nodes:
        _box(ax, pos[node.name], node.name, node.primitive.describe(), "#dbe9f6")
    for tr in skill.transitions:
        a, b = pos[tr.source], pos[tr.target]
        forward = b[0] > a[0] and order.index(tr.target) == order.index(tr.source) + 1
        rad = 0.0 if forward else -0.35
        dy = 0.05 if forward else 0.45
        _arrow(
            ax, (a[0] + 0.44, a[1]), (b[0] - 0.44, b[1]), tr.condition.describe(), rad=rad, dy=dy
        )
    last = pos[order[-1]]
    success = skill.success.describe()
    _arrow(ax, (last[0] + 0.44, 0.0), (end[0] - 0.16, 0.0), success, color="green", dy=0.05)
    if skill.recovery is not None:
        _draw_recovery(ax, skill, pos, ((pos[order[0]][0] + last[0]) / 2, -1.6), n)
    ax.text(
        0.0,
        1.05,
        f"skill {skill.name!r} — global error: {skill.error.describe()}",
        fontsize=8,
        color="firebrick",
        transform=ax.transData,
    )
    ax.text(0.0, 0.85, f"task frame: {skill.frame}", fontsize=7, color="0.3")
    _legend(ax)
    ax.set_xlim(-0.4, end[0] + 0.4)
    ax.set_ylim(-2.1, 1.25)
    ax.set_aspect("equal")
    ax.axis("off")
    return save_figure(fig, path, dpi=130)


def _draw_entry_and_exit(
    ax: plt.Axes, skill: Skill, pos: dict[str, tuple[float, float]], n: int
) -> tuple[float, float]:
    """The entry dot with the precondition's arrow and the success mark; returns the mark's
    position."""
    start, end = (0.0, 0.0), (_STEP * (n + 1), 0.0)
    ax.add_patch(plt.Circle(start, 0.12, color="k"))
    ax.add_patch(plt.Circle(end, 0.15, fc="white", ec="green", lw=3))
    ax.add_patch(plt.Circle(end, 0.09, color="green"))
    ax.text(end[0], end[1] - 0.3, "success", ha="center", fontsize=8, color="green")
    pre = skill.pre.describe() if skill.pre is not None else "always"
    _arrow(ax, (start[0] + 0.12, 0.0), (pos[skill.start][0] - 0.44, 0.0), f"pre: {pre}", dy=0.05)
    return end


def _draw_recovery(
    ax: plt.Axes,
    skill: Skill,
    pos: dict[str, tuple[float, float]],
    rec: tuple[float, float],
    n: int,
) -> None:
    """The recovery node at ``rec`` and every node's error exit to it (dashed, red)."""
    assert skill.recovery is not None
    recovery = f"recovery: {skill.recovery.name}"
    _box(ax, rec, recovery, skill.recovery.primitive.describe(), "#f6dbdb", half=0.7)
    for node in skill.nodes:
        a = pos[node.name]
        _arrow(
            ax,
            (a[0], a[1] - 0.33),
            (rec[0] + 0.5 * (a[0] - rec[0]) / n, rec[1] + 0.33),
            node.error.describe() if node.error else "",
            color="firebrick",
            style="--",
            dy=-0.1,
            frac=0.3,
        )


def _legend(ax: plt.Axes) -> None:
    from matplotlib.lines import Line2D

    entry = "entry (if the precondition holds)"
    ax.legend(
        handles=[
            Line2D([], [], ls="none", marker="o", color="k", label=entry),
            Line2D([], [], color="k", label="transition, when its condition holds"),
            Line2D([], [], color="green", label="success condition"),
            Line2D([], [], color="firebrick", ls="--", label="error condition -> recovery"),
        ],
        loc="upper right",
        fontsize=7,
        ncol=2,
        frameon=False,
    )


def plot_traces(traces: Sequence[ExecutionResult], path: str | Path, title: str = "") -> Path:
    """Executions over time: node timeline, contact force and depth (one column each);
    ``title`` should name the skill, task and seed."""
    path = Path(path)
    k = len(traces)
    fig, axes = plt.subplots(
        3,
        k,
        figsize=(4.6 * k, 7.5),
        squeeze=False,
        sharex="col",
        constrained_layout=True,
        height_ratios=(1.0, 1.6, 1.6),
    )
    names = sorted(
        {v.node for tr in traces for v in tr.visits},
        key=lambda n: next(i for tr in traces for i, v in enumerate(tr.visits) if v.node == n),
    )
    colors = {n: plt.cm.tab10(i % 10) for i, n in enumerate(names)}
    for j, tr in enumerate(traces):
        ax0, ax1, ax2 = axes[:, j]
        for i, v in enumerate(tr.visits):
            ax0.broken_barh(
                [(v.t_enter, max(v.t_exit - v.t_enter, 1e-3))], (i - 0.4, 0.8), color=colors[v.node]
            )
            ax0.text(v.t_exit, i, f" {v.node}", va="center", fontsize=7)
        ax0.set_yticks([])
        ax0.invert_yaxis()
        ax0.set_xlim(0.0, 1.2 * max(v.t_exit for v in tr.visits))  # room for the last name
        ok = "success" if tr.success else tr.outcome
        ax0.set_title(f"execution {j}: {ok}, contact at {tr.t_first_contact:.2f} s", fontsize=9)
        log = tr.log
        ax1.plot(log.t, log.wrench[:, 2], label="F_z")
        ax1.plot(log.t, np.hypot(log.wrench[:, 0], log.wrench[:, 1]), label="|F_xy|")
        ax1.set_ylabel("force on tool (N)")
        ax2.plot(log.t, log.depth * 1e3, color="k")
        ax2.set_ylabel("depth below est. entry (mm)")
        ax2.set_xlabel("time (s)")
        for ax in (ax1, ax2):
            for v in tr.visits:
                ax.axvline(v.t_enter, color=colors[v.node], lw=0.8, ls=":")
            ax.grid(alpha=0.3)
        if np.isfinite(tr.t_first_contact):
            ax1.axvline(tr.t_first_contact, color="r", lw=1.0, label="first contact")
        ax1.plot([], [], color="0.4", lw=0.8, ls=":", label="a node starts")
        ax1.legend(fontsize=7)
    if title:
        fig.suptitle(title, fontsize=10)
    return save_figure(fig, path)
