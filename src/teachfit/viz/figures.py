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
from teachfit.viz.output import save_figure


def _hole_patch(ax: plt.Axes, task: Task | None, scale: float) -> None:
    if task is None:
        return
    params = getattr(task, "params", None)
    radius = (
        (params.peg_diameter + params.clearance) / 2
        if hasattr(params, "peg_diameter") and hasattr(params, "clearance")
        else 0.002
    )
    hole = task.hole2world.pos
    ax.add_patch(
        Circle((hole[0] * scale, hole[1] * scale), radius * scale, fill=False, color="k", lw=1.5)
    )
    ax.plot(hole[0] * scale, hole[1] * scale, "k+", ms=10, label="hole")


def plot_demonstrations(
    demos: Sequence[Demonstration], path: str | Path, task: Task | None = None
) -> Path:
    """Paths over the hole (top view, mm) and the wrist wrench over time, one colour per demo."""
    path = Path(path)
    fig = plt.figure(figsize=(12, 5.5), constrained_layout=True)
    grid = fig.add_gridspec(3, 2, width_ratios=[1.1, 1.4])
    ax_xy = fig.add_subplot(grid[:, 0])
    axes_w = [fig.add_subplot(grid[i, 1]) for i in range(3)]
    colours = plt.cm.viridis(np.linspace(0.05, 0.85, max(1, len(demos))))
    for demo, c in zip(demos, colours, strict=False):
        label = demo.name or demo.source
        xy = demo.pos[:, :2] * 1e3
        ax_xy.plot(xy[:, 0], xy[:, 1], color=c, lw=1.0, label=label)
        ax_xy.plot(*xy[0], "o", color=c, ms=5)
        ax_xy.plot(*xy[-1], "s", color=c, ms=5)
        if demo.wrench is not None:
            f = demo.wrench
            axes_w[0].plot(demo.t, f[:, 0], color=c, lw=0.8)
            axes_w[1].plot(demo.t, f[:, 1], color=c, lw=0.8)
            axes_w[2].plot(demo.t, f[:, 2], color=c, lw=0.8)
    _hole_patch(ax_xy, task, 1e3)
    ax_xy.set_aspect("equal")
    ax_xy.set_xlabel("x (mm)")
    ax_xy.set_ylabel("y (mm)")
    ax_xy.set_title("paths over the hole (o start, s end)")
    ax_xy.legend(fontsize=7, loc="best")
    for ax, name in zip(axes_w, ("f_x", "f_y", "f_z"), strict=True):
        ax.set_ylabel(f"{name} (N)")
        ax.grid(alpha=0.3)
    axes_w[0].set_title("wrench the environment exerts on the tool (world frame)")
    axes_w[-1].set_xlabel("time (s)")
    return save_figure(fig, path)


def plot_executions(
    paths: Sequence[tuple[np.ndarray, bool]],
    path: str | Path,
    task: Task | None = None,
    title: str = "executions",
) -> Path:
    """Top view (mm) of executed TCP paths, green when inserted, red otherwise."""
    path = Path(path)
    fig, ax = plt.subplots(figsize=(6, 6), constrained_layout=True)
    for xyz, ok in paths:
        xy = np.asarray(xyz)[:, :2] * 1e3
        ax.plot(xy[:, 0], xy[:, 1], color="tab:green" if ok else "tab:red", lw=0.8, alpha=0.8)
        ax.plot(*xy[0], "o", color="0.3", ms=3)
    _hole_patch(ax, task, 1e3)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    n_ok = sum(ok for _, ok in paths)
    ax.set_title(f"{title}: {n_ok}/{len(paths)} inserted (green)")
    return save_figure(fig, path)
