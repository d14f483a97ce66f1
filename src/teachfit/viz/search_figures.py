"""Figures of the search method, in the style of the paper (matplotlib, Agg backend).

Every function returns a :class:`matplotlib.figure.Figure`; :func:`save` writes it. Lengths are
plotted in millimetres, rz in degrees.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from teachfit.models.exploration import ExplorationDistribution  # noqa: E402
from teachfit.trajectories.tshix import SearchTrajectory  # noqa: E402
from teachfit.viz.output import save_figure  # noqa: E402
from teachfit.viz.style import END, START, end_handles, mark_ends  # noqa: E402

_MM = 1e3


def _density_grid(expl: ExplorationDistribution, n: int = 120):
    lo, hi = expl.bounding_box(3.5)
    gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], n), np.linspace(lo[1], hi[1], n))
    if expl.dim == 2:
        pts = np.column_stack([gx.ravel(), gy.ravel()])
        z = expl.pdf(pts)
    else:  # marginal over the remaining dims of a Gaussian mixture: drop those rows/cols
        marg = ExplorationDistribution(
            expl.dims[:2], expl.weights, expl.means[:, :2], expl.covs[:, :2, :2]
        )
        z = marg.pdf(np.column_stack([gx.ravel(), gy.ravel()]))
    return gx * _MM, gy * _MM, z.reshape(gx.shape)


def samples_over_distribution(
    expl: ExplorationDistribution,
    rng: np.random.Generator,
    ns: Sequence[int] = (100, 200, 300, 400, 500),
    seed: int | None = None,
) -> Figure:
    """One panel per N: N samples of p_e over its density (x-y marginal)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    fig, axes = plt.subplots(1, len(ns), figsize=(3.2 * len(ns), 3.4), squeeze=False)
    gx, gy, z = _density_grid(expl)
    for ax, n in zip(axes[0], ns, strict=True):
        ax.contourf(gx, gy, z, levels=12, cmap="Blues")
        s = expl.sample(int(n), rng)
        ax.plot(s[:, 0] * _MM, s[:, 1] * _MM, ".", color="crimson", ms=2.5)
        ax.set_title(f"N = {n}")
        ax.set_xlabel("x (mm)")
        # the density's grid, not the samples, frames every panel (an outlier outside it
        # would widen one panel and leave a blank margin)
        ax.set_xlim(gx[0, 0], gx[0, -1])
        ax.set_ylim(gy[0, 0], gy[-1, 0])
        ax.set_aspect("equal")
    axes[0, 0].set_ylabel("y (mm)")
    fig.legend(
        handles=[
            Patch(color=plt.cm.Blues(0.6), label="exploration density (darker: likelier)"),
            Line2D([], [], ls="none", marker=".", color="crimson", label="i.i.d. sample"),
        ],
        loc="lower center",
        ncol=2,
        fontsize=8,
    )
    seeded = "" if seed is None else f", seed {seed}"
    fig.suptitle(f"samples of the exploration density, search frame{seeded}", fontsize=10)
    fig.subplots_adjust(left=0.3 / len(ns), right=0.99, bottom=0.2, top=0.85, wspace=0.3)
    return fig


def tshix_stages(
    traj: SearchTrajectory,
    expl: ExplorationDistribution | None = None,
    seed: int | None = None,
) -> Figure:
    """Three panels: samples, itinerary (open tour from the start), smoothed trajectory."""
    from matplotlib.lines import Line2D

    it, samples = traj.itinerary, traj.samples
    if it is None or samples is None:
        raise ValueError("trajectory has no samples / itinerary (not a TSHIX trajectory)")
    fig, axes = plt.subplots(1, 3, figsize=(11, 4.8), sharex=True, sharey=True)
    for ax in axes:
        if expl is not None:
            gx, gy, z = _density_grid(expl)
            ax.contour(gx, gy, z, levels=6, colors="0.75", linewidths=0.7)
        ax.plot(samples[:, 0] * _MM, samples[:, 1] * _MM, ".", color="crimson", ms=3)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
    axes[1].plot(it[:, 0] * _MM, it[:, 1] * _MM, "-", color="0.3", lw=0.8)
    mark_ends(axes[1], it[:, 0] * _MM, it[:, 1] * _MM)
    axes[2].plot(traj.states[:, 0] * _MM, traj.states[:, 1] * _MM, "-", color="navy", lw=1.0)
    mark_ends(axes[2], traj.states[:, 0] * _MM, traj.states[:, 1] * _MM)
    axes[0].plot(it[0, 0] * _MM, it[0, 1] * _MM, mec="k", **START)
    for ax, title in zip(axes, ("samples", "itinerary", "smoothed trajectory"), strict=True):
        ax.set_title(title)
    axes[0].set_ylabel("y (mm)")
    handles = [
        Line2D([], [], ls="none", marker=".", color="crimson", label="sample"),
        Line2D([], [], color="0.3", lw=0.8, label="itinerary (open tour)"),
        Line2D([], [], color="navy", label="smoothed trajectory"),
        *end_handles("k"),
    ]
    if expl is not None:
        handles.insert(0, Line2D([], [], color="0.75", lw=0.7, label="exploration density"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8)
    seeded = "" if seed is None else f", seed {seed}"
    fig.suptitle(
        f"TSHIX, N = {len(samples)}{seeded}: from samples to a trajectory (search frame; "
        "the start is the demonstration's first pose)",
        fontsize=10,
    )
    fig.subplots_adjust(left=0.07, right=0.99, bottom=0.2, top=0.86, wspace=0.08)
    return fig


def feedforward_arrows(traj: SearchTrajectory, wrench: np.ndarray, every: int = 50) -> Figure:
    """Trajectory with the predicted feed-forward force (wrench[:, :2], N) as arrows."""
    w = np.asarray(wrench, float)
    if w.shape[0] != traj.t.size:
        raise ValueError("wrench must have one row per trajectory sample")
    fig, ax = plt.subplots(figsize=(5.5, 5))
    ax.plot(traj.states[:, 0] * _MM, traj.states[:, 1] * _MM, color="0.5", lw=0.8)
    mark_ends(ax, traj.states[:, 0] * _MM, traj.states[:, 1] * _MM)
    ax.legend(handles=end_handles("k"), fontsize=8, loc="best")
    k = slice(0, None, max(1, int(every)))
    q = ax.quiver(
        traj.states[k, 0] * _MM,
        traj.states[k, 1] * _MM,
        w[k, 0],
        w[k, 1],
        np.linalg.norm(w[k, :2], axis=1),
        cmap="viridis",
        angles="xy",
    )
    fig.colorbar(q, ax=ax, label="|F_ff| (N)")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_aspect("equal")
    n = "" if traj.samples is None else f", N = {len(traj.samples)}"
    ax.set_title(
        f"{traj.method.replace('tshix', 'TSHIX')}{n}: GMR feed-forward force along the trajectory\n"
        f"(search frame; an arrow every {int(every)} set-points)",
        fontsize=10,
    )
    fig.tight_layout()
    return fig


def trajectory_3d(traj: SearchTrajectory) -> Figure:
    """(x, y, rz) trajectory for socket3d; colour = time."""
    if traj.states.shape[1] != 3:
        raise ValueError("need a 3-D (x, y, rz) trajectory")
    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(projection="3d")
    s = traj.states
    ax.plot(s[:, 0] * _MM, s[:, 1] * _MM, np.degrees(s[:, 2]), lw=0.7, color="navy")
    pts = (s[:, 0] * _MM, s[:, 1] * _MM, np.degrees(s[:, 2]))
    ax.plot(*[v[:1] for v in pts], mec="k", **START, label="start")
    ax.plot(*[v[-1:] for v in pts], color="k", **END, label="end")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("rz (deg)")
    ax.legend(fontsize=8)
    n = "" if traj.samples is None else f", N = {len(traj.samples)}"
    ax.set_title(f"{traj.method} search trajectory{n} (search frame)", fontsize=10)
    return fig


def planned_vs_executed(
    planned: np.ndarray, executed: np.ndarray, labels: Sequence[str] = ("planned", "executed")
) -> Figure:
    """Overlay of two (T, >=2) paths in the search plane."""
    p, e = np.asarray(planned, float), np.asarray(executed, float)
    fig, ax = plt.subplots(figsize=(5.5, 5))
    ax.plot(p[:, 0] * _MM, p[:, 1] * _MM, "--", color="0.4", lw=1.0, label=labels[0])
    ax.plot(e[:, 0] * _MM, e[:, 1] * _MM, "-", color="crimson", lw=1.0, label=labels[1])
    mark_ends(ax, p[:, 0] * _MM, p[:, 1] * _MM, "0.4")
    mark_ends(ax, e[:, 0] * _MM, e[:, 1] * _MM, "crimson")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_aspect("equal")
    handles, _ = ax.get_legend_handles_labels()
    ax.legend(handles=handles + end_handles(), fontsize=8)
    ax.set_title(f"{labels[0]} and {labels[1]} path (search frame)", fontsize=10)
    fig.tight_layout()
    return fig


def save(fig: Figure, path: str | Path, dpi: int = 150) -> Path:
    """Write a figure (format from the suffix) and close it."""
    return save_figure(fig, path, dpi=dpi)
