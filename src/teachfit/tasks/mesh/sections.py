"""Planar cross-sections of the parts: the hole, the held part's footprint, their clearance.

Frames: the fixed part in the hole frame (entry centre at the origin, z up out of the hole),
the held part in the TCP frame (tip at the origin, axis +z), lengths in metres. With the part
aligned (TCP at the hole frame), every horizontal section of the held part up to the success
depth must fit inside the hole's sections down to that depth. ``shapely`` does the exact
polygon algebra; sections come from ``trimesh.intersections.mesh_plane``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import reduce

import numpy as np
import shapely
import trimesh
from scipy.spatial import cKDTree
from shapely import affinity
from shapely.geometry.base import BaseGeometry

from teachfit.core.errors import TaskError

#: distance (m) within which section end points are one point
WELD = 1e-9
#: depth below the entry (m) of the section that finds the hole's opening
ENTRY_EPS = 5e-5
#: the least depth (m) the aligned part must enter a deeper hole before it stops: less is a
#: part larger than the hole (a chamfered tip enters a little), not a shoulder
MIN_ENTRY = 1e-3


def section(mesh: trimesh.Trimesh, z: float) -> BaseGeometry:
    """The solid's cross-section at height ``z`` (m) as a shapely (Multi)Polygon, even-odd
    filled (holes are interiors); empty where the plane misses the mesh."""
    segs = trimesh.intersections.mesh_plane(mesh, [0.0, 0.0, 1.0], [0.0, 0.0, z])
    if len(segs) == 0:
        return shapely.Polygon()
    lines = shapely.linestrings(_welded(segs[:, :, :2]))
    merged = shapely.line_merge(shapely.multilinestrings(lines))
    rings = [g for g in getattr(merged, "geoms", [merged]) if g.is_ring and len(g.coords) >= 4]
    polys = [shapely.Polygon(r.coords) for r in rings]
    polys = [p if p.is_valid else p.buffer(0) for p in polys]
    return reduce(lambda a, b: a.symmetric_difference(b), polys, shapely.Polygon())


def _welded(ends: np.ndarray) -> np.ndarray:
    """Segment end points (n, 2, 2) with every point within :data:`WELD` of a first one moved
    onto it, so the segments join into rings (rounding alone splits points either side of a
    rounding boundary)."""
    pts = ends.reshape(-1, 2)
    pairs = cKDTree(pts).query_pairs(WELD, output_type="ndarray")
    first = np.arange(len(pts))
    np.minimum.at(first, pairs[:, 1], pairs[:, 0])
    first = first[first[first]]  # a chain of near points ends on its first
    return pts[first].reshape(ends.shape)


def footprint(held: trimesh.Trimesh, height: float) -> BaseGeometry:
    """Union of the held part's sections (TCP frame) from just above its tip to ``height`` (m):
    the outline of what enters the hole."""
    zmax = float(held.vertices[:, 2].max())
    hs = np.linspace(2e-5, min(height, zmax - 2e-5), 12)
    return shapely.unary_union([section(held, h) for h in hs])


@dataclass(frozen=True)
class HoleFit:
    """How the aligned held part fits the hole (m, rad).

    ``clearance``: smallest gap per side between the footprint and the hole walls down to the
    success depth; ``hole_depth``: depth below the entry where the hole's bottom is (the part's
    bottom, i.e. the table, for a through hole); ``detection_radius``: lateral TCP offset within
    which the footprint stays over the top surface, off every other opening; ``rz_tolerance``:
    largest yaw error at which the footprint still fits; ``stop_depth``: how deep the aligned
    part's tip gets before it touches the fixed part or the table (:func:`stop_depth_of`);
    ``rz_period``: the fit's yaw symmetry (:func:`rz_period_of`; 0: any yaw fits).
    """

    clearance: float
    hole_depth: float
    detection_radius: float
    rz_tolerance: float
    stop_depth: float
    rz_period: float


def _walls(fixed: trimesh.Trimesh, depth: float) -> BaseGeometry:
    zs = -np.linspace(ENTRY_EPS, depth, max(4, int(np.ceil(depth / 5e-4)) + 1))
    return shapely.unary_union([section(fixed, z) for z in zs])


def hole_depth_of(fixed: trimesh.Trimesh) -> float:
    """Depth (m) below the entry at which material closes the hole axis (its bottom)."""
    bottom = -float(fixed.vertices[:, 2].min())
    origin = shapely.Point(0.0, 0.0)
    step = 5e-4
    for d in np.arange(ENTRY_EPS, bottom, step):
        if section(fixed, -d).contains(origin):
            lo, hi = max(d - step, ENTRY_EPS), float(d)
            while hi - lo > 1e-6:
                mid = (lo + hi) / 2
                lo, hi = (lo, mid) if section(fixed, -mid).contains(origin) else (mid, hi)
            return float(hi)
    return bottom


def check_entry(fixed: trimesh.Trimesh, where: str) -> BaseGeometry:
    """The section just below the entry; raise unless the hole frame sits at an opening.

    ``fixed`` is in the hole frame. Errors: the hole frame outside the part, inside solid
    material, or at no opening.
    """
    lo, hi = fixed.bounds
    margin = 1e-4
    if np.any(lo[:2] > margin) or np.any(hi[:2] < -margin) or lo[2] > margin or hi[2] < -margin:
        raise TaskError(
            f"{where}: the hole frame lies outside the fixed part (its bounds in the hole frame "
            f"are {np.round(1e3 * lo, 2)} .. {np.round(1e3 * hi, 2)} mm); fix hole_pos"
        )
    top = section(fixed, -ENTRY_EPS)
    origin = shapely.Point(0.0, 0.0)
    if top.is_empty:
        raise TaskError(f"{where}: no material just below the hole frame; fix hole_pos")
    if top.contains(origin):
        raise TaskError(
            f"{where}: the hole frame is inside solid material, not at a hole entry; fix "
            "hole_pos (the entry centre) or insertion_axis"
        )
    return top


def fit_of(
    fixed: trimesh.Trimesh,
    held: trimesh.Trimesh,
    success_depth: float,
    where: str,
    reach: tuple[float, float] | None = None,
) -> HoleFit:
    """The :class:`HoleFit` of the aligned held part; raise if it is larger than the hole or
    stops above ``success_depth``. ``reach``: the hole depth and the stop depth if known."""
    top = check_entry(fixed, where)
    depth, stop = reach if reach is not None else reach_of(fixed, held)
    if stop < min(depth, MIN_ENTRY) - 1e-9:
        raise TaskError(
            f"{where}: the held part is larger than the hole (aligned, it stops "
            f"{1e3 * stop:.2f} mm below the entry); check the meshes, units and grasp"
        )
    if success_depth > stop:
        what = "hole" if stop >= depth - 1e-6 else "place where the aligned part stops"
        raise TaskError(
            f"{where}: success_depth {1e3 * success_depth:.2f} mm is deeper than the {what} "
            f"({1e3 * stop:.2f} mm); lower success_depth"
        )
    foot = footprint(held, success_depth)
    if foot.is_empty:
        raise TaskError(f"{where}: the held part has no section above its tip; fix the grasp")
    walls = _walls(fixed, success_depth)
    if walls.intersects(foot):
        over = walls.intersection(foot).area
        raise TaskError(
            f"{where}: the held part is larger than the hole ({1e6 * over:.2f} mm^2 of its "
            "section overlaps the hole walls when aligned); check the meshes, units and grasp"
        )
    clearance = float(walls.distance(foot))
    radius = float(np.max(np.linalg.norm(np.asarray(shapely.get_coordinates(foot)), axis=1)))
    rings = [top.exterior] if top.geom_type == "Polygon" else [p.exterior for p in top.geoms]
    for poly in getattr(top, "geoms", [top]):
        rings += [r for r in poly.interiors if not shapely.Polygon(r).contains(foot)]
    origin = shapely.Point(0.0, 0.0)
    detect = max(min(float(r.distance(origin)) for r in rings) - radius, clearance)
    tol = _rz_tolerance(walls, foot)
    period = rz_period_of(walls, foot, tol, clearance)
    return HoleFit(clearance, depth, detect, tol, stop, period)


def reach_of(fixed: trimesh.Trimesh, held: trimesh.Trimesh) -> tuple[float, float]:
    """The hole depth (:func:`hole_depth_of`) and the stop depth (:func:`stop_depth_of`), m."""
    depth = hole_depth_of(fixed)
    return depth, stop_depth_of(fixed, held, depth)


def stop_depth_of(fixed: trimesh.Trimesh, held: trimesh.Trimesh, hole_depth: float) -> float:
    """Depth (m below the entry) of the aligned held part's tip where, sliding down the hole
    axis, it first touches the fixed part or the table (the plane under the fixed part).

    Both parts in the hole frame / TCP frame. The tip at depth ``d`` overlaps when some section
    of the held part at height ``h`` (2 um eroded, so touching flush walls is no overlap)
    meets the fixed part's section at ``h - d``; heights are sampled on one grid of ``step``
    (0.1 mm, or 1/200 of the fixed part's height if coarser), so a shoulder of the held part
    is found to within one step. The hole bottom on the axis (``hole_depth``) and the table
    are exact.
    """
    bottom = -float(fixed.vertices[:, 2].min())
    top = float(fixed.vertices[:, 2].max())
    step = max(1e-4, (top + bottom) / 200)
    length = float(held.vertices[:, 2].max())
    n_held = int(np.ceil(min(length, top + bottom) / step))
    held_secs = np.array([section(held, (k + 0.5) * step).buffer(-2e-6) for k in range(n_held)])
    shapely.prepare(held_secs)
    n_below, n_above = int(np.ceil(bottom / step)), int(np.ceil(top / step))
    # fixed_secs[j]: the fixed part's section at (j - n_below + 0.5) * step
    levels = (np.arange(-n_below, n_above) + 0.5) * step
    fixed_secs = np.array([section(fixed, float(z)) for z in levels])
    for m in range(int(np.floor(min(bottom, hole_depth) / step)) + 1):
        # tip at depth m * step: the held section k lies at (k - m + 0.5) * step
        k = np.arange(min(n_held, m + n_above))
        if np.any(shapely.intersects(held_secs[k], fixed_secs[k - m + n_below])):
            return float(min(m * step, hole_depth, bottom))
    return float(min(hole_depth, bottom))


def rz_period_of(
    walls: BaseGeometry, foot: BaseGeometry, rz_tolerance: float, clearance: float
) -> float:
    """The fit's yaw symmetry (rad): 0 where the footprint fits at every yaw (``rz_tolerance``
    is pi: a round part or hole), else the smallest 2 pi / n, n in 6, 4, 3, 2, at which the
    footprint turned about the hole axis clears the hole walls by at least half the aligned
    ``clearance`` (a square: pi / 2; a rectangle: pi), else 2 pi (no symmetry)."""
    if rz_tolerance >= np.pi:
        return 0.0
    for n in (6, 4, 3, 2):
        turned = affinity.rotate(foot, 2 * np.pi / n, origin=(0, 0), use_radians=True)
        if float(walls.distance(turned)) >= clearance / 2 and not walls.intersects(turned):
            return float(2 * np.pi / n)
    return float(2 * np.pi)


def _rz_tolerance(walls: BaseGeometry, foot: BaseGeometry) -> float:
    """Smallest yaw (rad) at which ``foot`` turned about the origin meets ``walls``, to 1e-6
    rad; pi where no turn does (a round part)."""

    def hits(a: float) -> bool:
        return bool(walls.intersects(affinity.rotate(foot, a, origin=(0, 0), use_radians=True)))

    grid = np.linspace(0.0, np.pi, 721)[1:]
    first = next((a for a in grid if hits(float(a))), None)
    if first is None:
        return float(np.pi)
    lo, hi = float(first - grid[0]), float(first)
    while hi - lo > 1e-6:
        mid = (lo + hi) / 2
        lo, hi = (lo, mid) if hits(mid) else (mid, hi)
    return lo
