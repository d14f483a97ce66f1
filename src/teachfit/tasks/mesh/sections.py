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
from shapely import affinity
from shapely.geometry.base import BaseGeometry

from teachfit.core.errors import TaskError

#: depth below the entry (m) of the section that finds the hole's opening
ENTRY_EPS = 5e-5


def section(mesh: trimesh.Trimesh, z: float) -> BaseGeometry:
    """The solid's cross-section at height ``z`` (m) as a shapely (Multi)Polygon, even-odd
    filled (holes are interiors); empty where the plane misses the mesh."""
    segs = trimesh.intersections.mesh_plane(mesh, [0.0, 0.0, 1.0], [0.0, 0.0, z])
    if len(segs) == 0:
        return shapely.Polygon()
    lines = shapely.linestrings(np.round(segs[:, :, :2], 10))
    merged = shapely.line_merge(shapely.multilinestrings(lines))
    rings = [g for g in getattr(merged, "geoms", [merged]) if g.is_ring and len(g.coords) >= 4]
    polys = [shapely.Polygon(r.coords) for r in rings]
    polys = [p if p.is_valid else p.buffer(0) for p in polys]
    return reduce(lambda a, b: a.symmetric_difference(b), polys, shapely.Polygon())


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
    bottom for a through hole); ``detection_radius``: lateral TCP offset within which the
    footprint stays over the top surface, off every other opening; ``rz_tolerance``: largest
    yaw error at which the footprint still fits.
    """

    clearance: float
    hole_depth: float
    detection_radius: float
    rz_tolerance: float


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
    fixed: trimesh.Trimesh, held: trimesh.Trimesh, success_depth: float, where: str
) -> HoleFit:
    """The :class:`HoleFit` of the aligned held part; raise if it is larger than the hole."""
    top = check_entry(fixed, where)
    depth = hole_depth_of(fixed)
    if success_depth > depth:
        raise TaskError(
            f"{where}: success_depth {1e3 * success_depth:.2f} mm is deeper than the hole "
            f"({1e3 * depth:.2f} mm); lower success_depth"
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
    reach = min(float(r.distance(origin)) for r in rings) - radius
    return HoleFit(clearance, depth, max(reach, clearance), _rz_tolerance(walls, foot))


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


def infer_hole(fixed: trimesh.Trimesh, held: trimesh.Trimesh) -> np.ndarray:
    """The entry centre (3,) (fixed mesh frame, m) of the opening in the fixed part's top face
    that the held part's footprint fits with the least clearance; insertion along -z."""
    top_z = float(fixed.vertices[:, 2].max())
    top = section(fixed, top_z - ENTRY_EPS)
    foot = footprint(held, 0.002)
    best: tuple[float, np.ndarray] | None = None
    for poly in getattr(top, "geoms", [top]):
        for ring in getattr(poly, "interiors", []):
            hole = shapely.Polygon(ring)
            c = hole.centroid
            placed = affinity.translate(foot, c.x, c.y)
            if hole.contains(placed):
                gap = float(hole.exterior.distance(placed))
                if best is None or gap < best[0]:
                    best = (gap, np.array([c.x, c.y, top_z]))
    if best is None:
        raise TaskError(
            "no opening in the fixed part's top face fits the held part; give the hole "
            "frame (--hole-pos, --insertion-axis)"
        )
    return best[1]
