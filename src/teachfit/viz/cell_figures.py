"""Figure of a mesh task's cell at true scale (lengths in mm, world frame, equal axes).

Left, the collision pieces in 3D (each piece its own colour from a qualitative map, dark
edges), the held part's pieces (orange) aligned above the hole, the hole frame. Middle, the fixed
part's walls down to the success depth seen from above: the mesh's hole outline (its real
shape and size, :mod:`teachfit.tasks.mesh.outline`), the decomposition's pieces cut at
mid-depth (one colour each), the held part's footprint and the detection radius. Right, a
zoom on the narrowest gap between the footprint and the walls: the clearance at the scale it
has. :func:`cell_axes` builds the figure, :func:`cell_figure` writes it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import shapely  # noqa: E402
import trimesh  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from mpl_toolkits.mplot3d import Axes3D  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402
from shapely.geometry.base import BaseGeometry  # noqa: E402
from shapely.ops import nearest_points  # noqa: E402

from teachfit.tasks.mesh.outline import hole_outline, walls_down_to  # noqa: E402
from teachfit.tasks.mesh.sections import footprint, section  # noqa: E402
from teachfit.tasks.mesh.task import MeshTask  # noqa: E402
from teachfit.viz.output import save_figure  # noqa: E402

__all__ = ["cell_axes", "cell_figure"]


#: tab20 without its oranges (the held part's colour)
_PALETTE = np.delete(plt.get_cmap("tab20")(np.arange(20)), [2, 3], axis=0)


def _colours(n: int) -> np.ndarray:
    """``n`` distinct colours (:data:`_PALETTE` cycled)."""
    return _PALETTE[np.arange(max(n, 1)) % len(_PALETTE)]


def _pieces(ax: Axes3D, pieces: list[np.ndarray], alpha: float, held: bool = False) -> None:
    """The pieces' hulls (m, drawn in mm), the held part's in shades of orange."""
    colours = plt.get_cmap("Oranges")(np.linspace(0.45, 0.8, max(len(pieces), 1)))
    for verts, color in zip(pieces, colours if held else _colours(len(pieces)), strict=False):
        hull = trimesh.Trimesh(verts).convex_hull
        tris = 1e3 * np.asarray(hull.vertices)[np.asarray(hull.faces)]
        ax.add_collection3d(
            Poly3DCollection(tris, facecolor=color, edgecolor=(0, 0, 0, 0.35), alpha=alpha)
        )


def _outline(ax: plt.Axes, geom: object, **kw: Any) -> None:
    for poly in getattr(geom, "geoms", [geom]):
        if poly.is_empty:
            continue
        for ring in [poly.exterior, *poly.interiors]:
            xy = 1e3 * np.asarray(ring.coords)
            ax.plot(xy[:, 0], xy[:, 1], **kw)
            kw.pop("label", None)


def _lines(ax: plt.Axes, geom: BaseGeometry, **kw: Any) -> None:
    """The (multi)line ``geom`` (m) in mm, labelled once."""
    for line in getattr(geom, "geoms", [geom]):
        if not line.is_empty and line.geom_type in ("LineString", "LinearRing"):
            xy = 1e3 * np.asarray(line.coords)
            ax.plot(xy[:, 0], xy[:, 1], **kw)
            kw.pop("label", None)


def _piece_sections(task: MeshTask) -> list[BaseGeometry]:
    """The fixed part's pieces cut halfway down to the success depth (hole frame, m)."""
    z = task.cell.hole2world.pos[2] - task.success_depth / 2
    out = []
    for verts in task.cell.fixture_pieces():
        if verts[:, 2].min() < z < verts[:, 2].max():
            hull = trimesh.Trimesh(verts - task.cell.hole2world.pos).convex_hull
            out.append(section(hull, -task.success_depth / 2))
    return out


def _view_3d(ax: Axes3D, task: MeshTask, lift: float) -> None:
    cell = task.cell
    hole = cell.hole2world
    _pieces(ax, cell.fixture_pieces(), 0.45)
    tcp = hole.matrix.copy()
    tcp[2, 3] += lift
    _pieces(ax, [v @ tcp[:3, :3].T + tcp[:3, 3] for v in cell.held_pieces_tcp()], 0.5, True)
    size = 0.5e3 * float(np.max(cell.fixed.extents))
    for k, color in enumerate(("r", "g", "b")):
        ax.quiver(*(1e3 * hole.pos), *(hole.rotation.apply(np.eye(3)[k]) * size * 0.5), color=color)
    lo = 1e3 * np.minimum(cell.fixed.bounds[0], hole.pos - lift)
    hi = 1e3 * np.maximum(cell.fixed.bounds[1], hole.pos + lift + cell.held_length)
    centre, half = (lo + hi) / 2, float(np.max(hi - lo)) / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=True):
        setter(c - half, c + half)
    ax.set_box_aspect((1.0, 1.0, 1.0))  # equal limits in an equal box: true scale
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    n_h, n_f = cell.held_pieces.n_pieces, cell.fixed_pieces.n_pieces
    ax.set_title(
        f"{cell.spec.label}: {n_f} fixed ({cell.fixed_pieces.method}) + {n_h} held pieces",
        fontsize=9,
    )


def _fill_pieces(ax: plt.Axes, cuts: list[BaseGeometry], window: BaseGeometry | None) -> None:
    """Each piece's section (m) filled in its own colour, clipped to ``window`` if given."""
    for geom, colour in zip(cuts, _colours(len(cuts)), strict=False):
        part = geom if window is None else geom.intersection(window)
        for poly in getattr(part, "geoms", [part]):
            if not poly.is_empty and poly.geom_type == "Polygon":
                xy = 1e3 * np.asarray(poly.exterior.coords)
                ax.fill(xy[:, 0], xy[:, 1], facecolor=colour, edgecolor="0.2", lw=0.5, alpha=0.6)


def _top_view(ax: plt.Axes, task: MeshTask, foot: BaseGeometry) -> None:
    """Pieces at mid-depth, the mesh's hole outline, the footprint (hole frame, mm)."""
    _fill_pieces(ax, _piece_sections(task), None)
    outline = hole_outline(task.cell)
    xy = 1e3 * (outline.xy - task.cell.hole2world.pos[:2])
    ax.plot(xy[:, 0], xy[:, 1], color="k", lw=1.2, label=outline.label())
    _outline(ax, foot, color="tab:orange", lw=1.2, label="held part footprint")
    radius = shapely.Point(0, 0).buffer(task.detection_radius)
    _outline(ax, radius, color="0.5", linestyle=":", label="detection radius")
    ax.set_aspect("equal")
    ax.set_xlabel("hole frame x (mm)")
    ax.set_ylabel("hole frame y (mm)")
    ax.set_title("from above: walls down to the success depth; pieces at mid-depth", fontsize=9)
    ax.legend(loc="upper right", fontsize=7)


def _zoom(ax: plt.Axes, task: MeshTask, foot: BaseGeometry, walls: BaseGeometry) -> None:
    """The narrowest gap between the footprint and the walls, a few clearances wide (mm)."""
    cell = task.cell
    a, b = nearest_points(foot.boundary, walls)
    mid = 1e3 * np.array([(a.x + b.x) / 2, (a.y + b.y) / 2])
    half = 1e3 * max(4 * cell.fit.clearance, 2e-5)
    window = shapely.box(*(mid - half) / 1e3, *(mid + half) / 1e3)
    _fill_pieces(ax, _piece_sections(task), window)
    _lines(ax, walls.boundary.intersection(window), color="k", lw=1.2, label="mesh walls")
    _lines(ax, foot.boundary.intersection(window), color="tab:orange", lw=1.2, label="footprint")
    ax.plot(1e3 * np.array([a.x, b.x]), 1e3 * np.array([a.y, b.y]), "r-", lw=1)
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_aspect("equal")
    ax.set_xlabel("hole frame x (mm)")
    ax.set_title(
        f"narrowest gap: {1e3 * cell.fit.clearance:.3f} mm per side in the mesh, "
        f"{1e3 * cell.fidelity.pieces_clearance:.3f} mm in the pieces",
        fontsize=9,
    )
    ax.legend(loc="upper right", fontsize=7)


def cell_axes(task: MeshTask, lift: float = 0.01) -> Figure:
    """The figure (see the module docstring); the held part drawn ``lift`` (m) above the hole."""
    fig = plt.figure(figsize=(17, 5.8))
    grid = fig.add_gridspec(1, 3, width_ratios=[1.2, 1.0, 1.0])
    _view_3d(fig.add_subplot(grid[0], projection="3d"), task, lift)
    foot = footprint(task.cell.held, task.success_depth)
    walls = walls_down_to(task.cell, task.success_depth)
    _top_view(fig.add_subplot(grid[1]), task, foot)
    _zoom(fig.add_subplot(grid[2]), task, foot, walls)
    fig.tight_layout()
    return fig


def cell_figure(task: MeshTask, path: str | Path, lift: float = 0.01) -> Path:
    """Write :func:`cell_axes`'s figure to ``path`` (png, pdf, ...)."""
    return save_figure(cell_axes(task, lift), path, dpi=110)
