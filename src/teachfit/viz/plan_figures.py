"""Figures of the planning tasks: parts with dimensions, a path as a strip of poses, and the
fitted pose parameter with ranked key poses (paper Fig. 6)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import trimesh  # noqa: E402
from mpl_toolkits.mplot3d import Axes3D  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from teachfit.core.geometry import Pose  # noqa: E402
from teachfit.plans.keyposes import KeyPoses  # noqa: E402
from teachfit.tasks.parts import Assembly  # noqa: E402
from teachfit.viz.output import save_figure

__all__ = ["add_mesh", "keypose_figure", "parts_figure", "path_strip_figure"]

MOVING_COLOR = (0.85, 0.45, 0.15)
FIXED_COLOR = (0.55, 0.6, 0.7)


def add_mesh(
    ax: Axes3D,
    mesh: trimesh.Trimesh,
    T: np.ndarray | None = None,
    *,
    color=FIXED_COLOR,
    alpha: float = 0.35,
) -> Poly3DCollection:
    """Draw a trimesh (vertices in m) transformed by ``T`` (4, 4) on a 3-D axis, in mm."""
    v = np.asarray(mesh.vertices) @ (np.eye(3) if T is None else T[:3, :3]).T
    if T is not None:
        v = v + T[:3, 3]
    coll = Poly3DCollection(
        1e3 * v[np.asarray(mesh.faces)],
        facecolor=color,
        alpha=alpha,
        edgecolor=(0.2, 0.2, 0.2, 0.15),
        linewidth=0.2,
    )
    ax.add_collection3d(coll)
    return coll


def _frame_axes(ax: Axes3D, asm: Assembly, extra: np.ndarray | None = None) -> None:
    pts = [asm.fixed.vertices, (asm.moving.vertices @ asm.goal[:3, :3].T) + asm.goal[:3, 3]]
    if extra is not None:
        pts.append(extra)
    allp = 1e3 * np.concatenate(pts)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    c, r = (lo + hi) / 2, (hi - lo).max() / 2
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")


def _save(fig: plt.Figure, path: str | Path | None) -> plt.Figure:
    if path is not None:
        save_figure(fig, path, dpi=120, bbox_inches="tight")
    return fig


def _parts_legend(fig: plt.Figure) -> None:
    from matplotlib.patches import Patch

    fig.legend(
        handles=[
            Patch(color=MOVING_COLOR, label="moving part L"),
            Patch(color=FIXED_COLOR, alpha=0.5, label="fixed part G"),
        ],
        loc="lower center",
        ncol=2,
        fontsize=8,
        frameon=False,
    )


def parts_figure(asm: Assembly, path: str | Path | None = None) -> plt.Figure:
    """The parts at the goal pose in 3-D, the moving part alone, and a table of dimensions."""
    fig = plt.figure(figsize=(12, 4.5))
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    add_mesh(ax, asm.fixed)
    add_mesh(ax, asm.moving, asm.goal, color=MOVING_COLOR, alpha=0.8)
    _frame_axes(ax, asm)
    ax.set_title(f"{asm.task}: assembled (frame G)")
    ax2 = fig.add_subplot(1, 3, 2, projection="3d")
    add_mesh(ax2, asm.moving, color=MOVING_COLOR, alpha=0.8)
    v = 1e3 * asm.moving.vertices
    c, r = (v.min(0) + v.max(0)) / 2, np.ptp(v, axis=0).max() / 2
    ax2.set_xlim(c[0] - r, c[0] + r)
    ax2.set_ylim(c[1] - r, c[1] + r)
    ax2.set_zlim(c[2] - r, c[2] + r)
    for axis, name in zip("xyz", ("x", "y", "z"), strict=True):
        getattr(ax2, f"set_{axis}label")(f"{name} (mm)")
    ax2.set_title("moving part (frame L)")
    _parts_legend(fig)
    ax3 = fig.add_subplot(1, 3, 3)
    ax3.axis("off")
    rows = [[k.replace("_", " "), f"{1e3 * v:.1f}"] for k, v in asm.dimensions.items()]
    table = ax3.table(cellText=rows, colLabels=["dimension", "mm"], loc="center")
    table.scale(1.0, 1.3)
    ax3.set_title("dimensions")
    return _save(fig, path)


def path_strip_figure(
    asm: Assembly, path: Sequence[Pose], n: int = 6, out: str | Path | None = None
) -> plt.Figure:
    """The path as a strip of ``n`` poses evenly spaced along it.

    Parameters
    ----------
    path : sequence of Pose
        Poses ``L2G`` of the moving part in ``G`` (m), e.g. :meth:`MotionPlanner.dense_poses`.
    """
    positions = np.stack([p.pos for p in path])
    idx = np.unique(np.linspace(0, len(path) - 1, n).round().astype(int))
    fig = plt.figure(figsize=(3.2 * len(idx), 3.4))
    for k, i in enumerate(idx):
        ax = fig.add_subplot(1, len(idx), k + 1, projection="3d")
        add_mesh(ax, asm.fixed)
        add_mesh(ax, asm.moving, path[i].matrix, color=MOVING_COLOR, alpha=0.85)
        _frame_axes(ax, asm, extra=positions)
        ax.view_init(elev=20, azim=-70)
        ax.set_title(f"pose {k + 1}/{len(idx)}", fontsize=9)
        ax.tick_params(labelsize=6)
    fig.suptitle(
        f"{asm.task}: the planned path of L in G, {len(idx)} poses evenly spaced along it "
        "(axes in mm)",
        fontsize=10,
    )
    _parts_legend(fig)
    return _save(fig, out)


def keypose_figure(keys: KeyPoses, out: str | Path | None = None) -> plt.Figure:
    """The demonstrated parameter, its polynomial fit, and the candidates with their ranks."""
    angular = keys.param in ("roll", "pitch", "yaw")
    scale, unit = (np.degrees(1.0), "deg") if angular else (1e3, "mm")
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(keys.demo_t, scale * keys.demo_values, ".", ms=3, color="0.6", label="demonstration")
    tt = np.linspace(keys.demo_t[0], keys.demo_t[-1], 400)
    ax.plot(
        tt,
        scale * keys.poly(tt),
        "-",
        color="C0",
        label=f"polynomial fit (deg {keys.poly.degree()})",
    )
    ax.plot(keys.t, scale * keys.poly(keys.t), "o", color="C3", label="candidate key poses")
    for t, v, rank, d in zip(keys.t, keys.poly(keys.t), keys.ranks, keys.derivative, strict=True):
        ax.annotate(
            f"{rank}",
            (t, scale * v),
            textcoords="offset points",
            xytext=(4, 6),
            fontsize=9,
            color="C3",
        )
        ax.plot(
            [t - 0.15, t + 0.15],
            scale * np.array([v - 0.15 * d, v + 0.15 * d]),
            "-",
            color="C3",
            lw=1,
        )
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"{keys.param} ({unit})")
    ax.set_title("key poses ranked by |derivative| of the fit (1 = inserted first)")
    ax.legend(fontsize=8)
    return _save(fig, out)
