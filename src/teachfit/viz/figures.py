"""Figures of demonstrations and executions (matplotlib, Agg backend: no display needed)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

from teachfit.demonstrations.dataset import Demonstration  # noqa: E402
from teachfit.tasks.base import Task  # noqa: E402
from teachfit.viz.output import save_figure  # noqa: E402
from teachfit.viz.style import axis_label, end_handles, mark_ends  # noqa: E402


def _hole_patch(ax: plt.Axes, task: Task | None, scale: float) -> None:
    """The task's hole seen from above: a mesh task's real outline (its cross-section), a
    round-peg cell's circle, else a nominal 4 mm circle; and the hole axis."""
    if task is None:
        return
    hole = task.hole2world.pos
    cell = getattr(task, "cell", None)
    if cell is not None:  # a mesh task: its hole as its meshes have it
        from teachfit.tasks.mesh.outline import hole_outline

        outline = hole_outline(cell)
        xy = outline.xy * scale
        ax.plot(xy[:, 0], xy[:, 1], color="k", lw=1.5, label=outline.label())
    else:
        params = getattr(task, "params", None)
        radius = (
            (params.peg_diameter + params.clearance) / 2
            if params is not None
            and hasattr(params, "peg_diameter")
            and hasattr(params, "clearance")
            else 0.002
        )
        ax.add_patch(
            Circle(
                (hole[0] * scale, hole[1] * scale),
                radius * scale,
                fill=False,
                color="k",
                lw=1.5,
                label=f"hole, Ø {2e3 * radius:.1f} mm",
            )
        )
    ax.plot(hole[0] * scale, hole[1] * scale, "k+", ms=10, label="hole axis")


def plot_demonstrations(
    demos: Sequence[Demonstration], path: str | Path, task: Task | None = None
) -> Path:
    """Paths seen from above (mm) and the force on the tool over time, one colour per demo,
    drawn in the demonstrations' own frame: the task's hole only where that frame is the
    task's world (an imported base-frame log is not moved onto world axes)."""
    path = Path(path)
    fig = plt.figure(figsize=(12, 5.5), constrained_layout=True)
    grid = fig.add_gridspec(3, 2, width_ratios=[1.1, 1.4])
    ax_xy = fig.add_subplot(grid[:, 0])
    axes_w = [fig.add_subplot(grid[i, 1]) for i in range(3)]
    colours = plt.cm.viridis(np.linspace(0.05, 0.85, max(1, len(demos))))
    frames = sorted({d.frame for d in demos})
    frame = frames[0] if len(frames) == 1 else "mixed frames"
    for demo, c in zip(demos, colours, strict=False):
        label = demo.name or demo.source
        xy = demo.pos[:, :2] * 1e3
        ax_xy.plot(xy[:, 0], xy[:, 1], color=c, lw=1.0, label=label)
        mark_ends(ax_xy, xy[:, 0], xy[:, 1], c)
        if demo.wrench is not None:
            f = demo.wrench
            axes_w[0].plot(demo.t, f[:, 0], color=c, lw=0.8)
            axes_w[1].plot(demo.t, f[:, 1], color=c, lw=0.8)
            axes_w[2].plot(demo.t, f[:, 2], color=c, lw=0.8)
    if frame == "world":
        _hole_patch(ax_xy, task, 1e3)
    ax_xy.set_aspect("equal")
    ax_xy.set_xlabel(axis_label("x", "mm", frame))
    ax_xy.set_ylabel(axis_label("y", "mm", frame))
    where = "over the hole" if frame == "world" and task is not None else "seen from above"
    task_name = ", ".join(sorted({d.task for d in demos}))
    ax_xy.set_title(f"{len(demos)} demonstration(s) of {task_name}: paths {where}")
    handles, _ = ax_xy.get_legend_handles_labels()
    ax_xy.legend(handles=handles + end_handles(), fontsize=7, loc="best")
    for ax, name in zip(axes_w, ("F_x", "F_y", "F_z"), strict=True):
        ax.set_ylabel(f"{name} (N)")
        ax.grid(alpha=0.3)
    if not any(d.wrench is not None for d in demos):
        axes_w[1].text(0.5, 0.5, "no force recorded", ha="center", transform=axes_w[1].transAxes)
    axes_w[0].set_title(f"force the environment exerts on the tool (in {frame})")
    axes_w[-1].set_xlabel("time (s)")
    return save_figure(fig, path)


def plot_executions(
    paths: Sequence[tuple[np.ndarray, bool]],
    path: str | Path,
    task: Task | None = None,
    title: str = "executions",
) -> Path:
    """Top view (mm, task world) of executed TCP paths, green when inserted, red otherwise;
    ``title`` should name the method, N and seed."""
    from matplotlib.lines import Line2D

    path = Path(path)
    fig, ax = plt.subplots(figsize=(6.4, 6.4), constrained_layout=True)
    for xyz, ok in paths:
        xy = np.asarray(xyz)[:, :2] * 1e3
        colour = "tab:green" if ok else "tab:red"
        ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=0.8, alpha=0.8)
        mark_ends(ax, xy[:, 0], xy[:, 1], colour)
    _hole_patch(ax, task, 1e3)
    ax.set_aspect("equal")
    ax.set_xlabel(axis_label("x", "mm", "world"))
    ax.set_ylabel(axis_label("y", "mm", "world"))
    n_ok = sum(ok for _, ok in paths)
    ax.set_title(f"{title}: {n_ok}/{len(paths)} inserted", fontsize=10)
    handles, _ = ax.get_legend_handles_labels()
    handles += [
        Line2D([], [], color="tab:green", label="inserted"),
        Line2D([], [], color="tab:red", label="not inserted"),
        *end_handles(),
    ]
    ax.legend(handles=handles, fontsize=7, loc="best")
    return save_figure(fig, path)
