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
from teachfit.viz.output import save_figure

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
) -> Figure:
    """One panel per N: N samples of p_e over its density (x-y marginal)."""
    fig, axes = plt.subplots(1, len(ns), figsize=(3.2 * len(ns), 3.2), squeeze=False)
    gx, gy, z = _density_grid(expl)
    for ax, n in zip(axes[0], ns, strict=True):
        ax.contourf(gx, gy, z, levels=12, cmap="Blues")
        s = expl.sample(int(n), rng)
        ax.plot(s[:, 0] * _MM, s[:, 1] * _MM, ".", color="crimson", ms=2.5)
        ax.set_title(f"N = {n}")
        ax.set_xlabel("x [mm]")
        ax.set_aspect("equal")
    axes[0, 0].set_ylabel("y [mm]")
    fig.tight_layout()
    return fig


def tshix_stages(traj: SearchTrajectory, expl: ExplorationDistribution | None = None) -> Figure:
    """Three panels: samples, itinerary (open tour from the start), smoothed trajectory."""
    it = traj.itinerary
    if it is None:
        raise ValueError("trajectory has no samples / itinerary (not a TSHIX trajectory)")
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.8), sharex=True, sharey=True)
    for ax in axes:
        if expl is not None:
            gx, gy, z = _density_grid(expl)
            ax.contour(gx, gy, z, levels=6, colors="0.8", linewidths=0.7)
        ax.plot(traj.samples[:, 0] * _MM, traj.samples[:, 1] * _MM, ".", color="crimson", ms=3)
        ax.plot(it[0, 0] * _MM, it[0, 1] * _MM, "k*", ms=10)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
    axes[1].plot(it[:, 0] * _MM, it[:, 1] * _MM, "-", color="0.3", lw=0.8)
    axes[2].plot(traj.states[:, 0] * _MM, traj.states[:, 1] * _MM, "-", color="navy", lw=1.0)
    for ax, title in zip(axes, ("samples", "itinerary", "smoothed trajectory"), strict=True):
        ax.set_title(title)
    axes[0].set_ylabel("y [mm]")
    fig.tight_layout()
    return fig


def feedforward_arrows(traj: SearchTrajectory, wrench: np.ndarray, every: int = 50) -> Figure:
    """Trajectory with the predicted feed-forward force (wrench[:, :2], N) as arrows."""
    w = np.asarray(wrench, float)
    if w.shape[0] != traj.t.size:
        raise ValueError("wrench must have one row per trajectory sample")
    fig, ax = plt.subplots(figsize=(5.5, 5))
    ax.plot(traj.states[:, 0] * _MM, traj.states[:, 1] * _MM, color="0.5", lw=0.8)
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
    fig.colorbar(q, ax=ax, label="|f_ff| [N]")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_aspect("equal")
    ax.set_title("feed-forward force along the trajectory")
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
    ax.scatter(
        *[v[:1] for v in (s[:, 0] * _MM, s[:, 1] * _MM, np.degrees(s[:, 2]))],
        color="k",
        marker="*",
        s=60,
    )
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_zlabel("rz [deg]")
    ax.set_title(f"{traj.method} search trajectory")
    return fig


def planned_vs_executed(
    planned: np.ndarray, executed: np.ndarray, labels: Sequence[str] = ("planned", "executed")
) -> Figure:
    """Overlay of two (T, >=2) paths in the search plane."""
    p, e = np.asarray(planned, float), np.asarray(executed, float)
    fig, ax = plt.subplots(figsize=(5.5, 5))
    ax.plot(p[:, 0] * _MM, p[:, 1] * _MM, "--", color="0.4", lw=1.0, label=labels[0])
    ax.plot(e[:, 0] * _MM, e[:, 1] * _MM, "-", color="crimson", lw=1.0, label=labels[1])
    ax.plot(p[0, 0] * _MM, p[0, 1] * _MM, "k*", ms=10)
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_aspect("equal")
    ax.legend()
    fig.tight_layout()
    return fig


def save(fig: Figure, path: str | Path, dpi: int = 150) -> Path:
    """Write a figure (format from the suffix) and close it."""
    return save_figure(fig, path, dpi=dpi)
