"""The figure of a run log: pose, set-point, wrench, depth and active node over time."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402

from teachfit.core.geometry import rz_from_quat  # noqa: E402
from teachfit.execution.recording import RunLog  # noqa: E402
from teachfit.viz.output import save_figure

MAX_EPISODES = 8


def plot_run(run: RunLog, path: str | Path, episodes: Sequence[int] | None = None) -> Path:
    """Draw ``episodes`` (default: the first :data:`MAX_EPISODES`) of ``run`` over time, one
    colour each: TCP x and y relative to the episode's start (mm; measured solid, set-point
    dotted), yaw (deg, tasks that turn), depth below the hole entry (mm), contact force (N;
    |F| solid, F_z dashed) and the active node. Returns the path written."""
    path = Path(path)
    chosen = list(range(min(len(run.episodes), MAX_EPISODES))) if episodes is None else episodes
    eps = [run.episodes[i] for i in chosen]
    yaw = [np.degrees(rz_from_quat(e.result.log.quat)) for e in eps]
    turns = any(y.size and np.ptp(np.unwrap(y, period=360)) > 0.5 for y in yaw)
    labels = ["Δx (mm)", "Δy (mm)"] + (["Δyaw (deg)"] if turns else [])
    labels += ["depth below entry (mm)", "force (N)", "node"]
    nodes = list(dict.fromkeys(v.node for e in eps for v in e.result.visits))  # first visit first
    fig, axes = plt.subplots(
        len(labels),
        1,
        figsize=(9, 1.7 * len(labels) + 0.3 * len(nodes)),
        sharex=True,
        height_ratios=[1.0] * (len(labels) - 1) + [0.3 + 0.25 * len(nodes)],
    )
    for k, (i, ep) in enumerate(zip(chosen, eps, strict=True)):
        if ep.result.log.n_samples:
            _draw_episode(
                axes,
                run,
                i,
                0.25 * k / len(eps),
                plt.cm.tab10(k % 10),
                yaw[k] if turns else None,
                nodes,
            )
    _label_axes(axes, labels, nodes, bool(eps))
    shown = f"{len(eps)} of {len(run.episodes)} episodes" if len(eps) < len(run.episodes) else ""
    info = run.info
    axes[0].set_title(
        f"{info.kind} {info.method} on {info.task} ({info.robot}, seed {info.seed})"
        + (f": {shown}" if shown else "")
        + "\nmotion from each start: measured solid, set-point dotted; |F| solid, F_z dashed",
        fontsize=10,
    )
    # fixed margins: a layout engine would draw the figure twice
    fig.subplots_adjust(left=0.11, right=0.98, bottom=0.5 / fig.get_figheight(), hspace=0.12)
    fig.subplots_adjust(top=1 - 0.55 / fig.get_figheight())
    return save_figure(fig, path, dpi=110)


def _draw_episode(
    axes: Sequence[Axes],
    run: RunLog,
    i: int,
    lane_offset: float,
    c: object,
    yaw: np.ndarray | None,
    nodes: list[str],
) -> None:
    """Episode ``i`` of ``run`` in colour ``c`` on every panel: its yaw (deg, None: no yaw
    panel) and its active node, one lane per node, shifted by ``lane_offset`` in [0, 0.25)."""
    ep = run.episodes[i]
    r, log = ep.result, ep.result.log
    rel, sp = (log.pos - log.pos[0]) * 1e3, (log.setpoint_pos - log.pos[0]) * 1e3
    outcome = "success" if r.success else r.outcome.value
    axes[0].plot(log.t, rel[:, 0], color=c, lw=1.2, label=f"#{i} {outcome} ({r.t_end:.1f} s)")
    axes[0].plot(log.t, sp[:, 0], color=c, lw=0.8, ls=":")
    axes[1].plot(log.t, rel[:, 1], color=c, lw=1.2)
    axes[1].plot(log.t, sp[:, 1], color=c, lw=0.8, ls=":")
    row = 2
    if yaw is not None:
        axes[row].plot(log.t, np.unwrap(yaw - yaw[0], period=360), color=c, lw=1.2)
        row += 1
    axes[row].plot(log.t, run.depth(i) * 1e3, color=c, lw=1.2)
    axes[row + 1].plot(log.t, np.linalg.norm(log.wrench[:, :3], axis=1), color=c, lw=1.2)
    axes[row + 1].plot(log.t, log.wrench[:, 2], color=c, lw=0.8, ls="--")
    visit_at = np.searchsorted([v.t_enter for v in r.visits], log.t, side="right") - 1
    active = [nodes.index(r.visits[j].node) if j >= 0 else np.nan for j in visit_at]
    lane = np.asarray(active, float) + lane_offset
    axes[row + 2].step(log.t, lane, where="post", color=c)


def _label_axes(axes: Sequence[Axes], labels: list[str], nodes: list[str], legend: bool) -> None:
    """Y labels and grids; the node panel's lanes; the time axis; the legend if ``legend``."""
    for ax, label in zip(axes, labels, strict=True):
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[-1].set_yticks(range(len(nodes)), nodes)
    axes[-1].set_ylim(max(len(nodes), 1) - 0.4, -0.4)
    axes[-1].set_xlabel("time since the episode started (s)")
    if legend:
        axes[0].legend(fontsize=7, ncol=2, loc="best")
