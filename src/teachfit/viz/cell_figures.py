"""Figure of a mesh task's cell: the collision pieces, the held part, the hole frame, and the
section at the hole entry with the part's footprint (lengths in mm, world frame)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import shapely  # noqa: E402
import trimesh  # noqa: E402
from mpl_toolkits.mplot3d import Axes3D  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from teachfit.tasks.mesh.sections import ENTRY_EPS, footprint, section  # noqa: E402
from teachfit.tasks.mesh.task import MeshTask  # noqa: E402
from teachfit.viz.output import save_figure

__all__ = ["cell_figure"]


def _pieces(ax: Axes3D, pieces: list[np.ndarray], cmap: str, alpha: float) -> None:
    colors = plt.get_cmap(cmap)(np.linspace(0.25, 0.85, max(len(pieces), 1)))
    for verts, color in zip(pieces, colors, strict=False):
        hull = trimesh.Trimesh(verts).convex_hull
        tris = 1e3 * np.asarray(hull.vertices)[np.asarray(hull.faces)]
        ax.add_collection3d(
            Poly3DCollection(tris, facecolor=color, edgecolor=(0, 0, 0, 0.15), alpha=alpha)
        )


def _outline(ax: plt.Axes, geom: object, **kw: Any) -> None:
    for poly in getattr(geom, "geoms", [geom]):
        if poly.is_empty:
            continue
        for ring in [poly.exterior, *poly.interiors]:
            xy = 1e3 * np.asarray(ring.coords)
            ax.plot(xy[:, 0], xy[:, 1], **kw)


def cell_figure(task: MeshTask, path: str | Path, lift: float = 0.01) -> Path:
    """Write a png: left the fixed part's convex pieces (one colour each) and the held part's
    pieces aligned ``lift`` (m) above the hole, with the hole frame's axes; right the fixed
    part's section just below the entry and the held part's footprint, aligned."""
    cell = task.cell
    hole = cell.hole2world
    fig = plt.figure(figsize=(12, 5.5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    _pieces(ax, cell.fixture_pieces(), "Blues", 0.35)
    tcp = hole.matrix.copy()
    tcp[2, 3] += lift
    held = [v @ tcp[:3, :3].T + tcp[:3, 3] for v in cell.held_pieces_tcp()]
    _pieces(ax, held, "Oranges", 0.6)
    size = 0.5e3 * float(np.max(cell.fixed.extents))
    for k, color in enumerate(("r", "g", "b")):
        axis = hole.rotation.apply(np.eye(3)[k]) * size * 0.5
        p = 1e3 * hole.pos
        ax.quiver(*p, *axis, color=color, linewidth=2)
    lo = 1e3 * np.minimum(cell.fixed.bounds[0], hole.pos - lift)
    hi = 1e3 * np.maximum(cell.fixed.bounds[1], hole.pos + lift + cell.held_length)
    centre, half = (lo + hi) / 2, float(np.max(hi - lo)) / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=True):
        setter(c - half, c + half)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    n_h, n_f = cell.held_pieces.n_pieces, cell.fixed_pieces.n_pieces
    ax.set_title(f"{cell.spec.label}: {n_f} fixed + {n_h} held convex pieces; hole frame rgb")
    ax2 = fig.add_subplot(1, 2, 2)
    fixed_h = cell.fixed.copy()
    fixed_h.apply_translation(-hole.pos)
    _outline(ax2, section(fixed_h, -ENTRY_EPS), color="tab:blue", label="fixed part at entry")
    foot = footprint(cell.held, task.success_depth)
    _outline(ax2, foot, color="tab:orange", label="held part footprint")
    walls = shapely.Point(0, 0).buffer(task.detection_radius)
    _outline(ax2, walls, color="0.5", linestyle=":", label="detection radius")
    ax2.set_aspect("equal")
    ax2.set_xlabel("hole frame x (mm)")
    ax2.set_ylabel("hole frame y (mm)")
    ax2.set_title(
        f"clearance {1e3 * cell.fit.clearance:.3f} mm per side "
        f"({1e3 * cell.fidelity.pieces_clearance:.3f} mm after decomposition)"
    )
    handles, labels = ax2.get_legend_handles_labels()
    unique = dict(zip(labels, handles, strict=True))
    ax2.legend(unique.values(), unique.keys(), loc="upper right", fontsize=8)
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)
