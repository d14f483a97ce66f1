"""Convex pieces of the ``socket3d`` cell: valley wedges around a hole, floor fillers, pins.

MuJoCo collides a mesh as its convex hull, so each builder returns the vertices of one convex
piece whose hull is exactly the intended solid:

* :func:`valley_wedge` -- one angular wedge of a square floor tile around a hole. Its top
  falls linearly towards the hole *along the wedge's bisector* (a plane), clipped at the flat
  floor height. The top is the minimum of two affine functions, so it is concave and the solid
  below it (its hypograph) is convex. ``K`` wedges around a hole form a faceted funnel (a
  "valley") leading into a polygonal hole that circumscribes the nominal hole circle.
* :func:`disc_segment` -- a prism over a disc cut by half-planes (floor outside the tiles).
* :func:`rounded_pin` -- a cylinder along +z with a rounded (quarter-circle) tip edge at ``z=0``.

All lengths are in metres, in the frame of the body the geom is attached to (z up).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def _square_exit(direction: np.ndarray, half_width: float) -> float:
    """Distance from a square's centre to its boundary along a unit ``direction`` (m)."""
    return half_width / max(abs(direction[0]), abs(direction[1]))


def valley_wedge(
    centre: tuple[float, float],
    angle0: float,
    angle1: float,
    r_hole: float,
    half_width: float,
    z_bottom: float,
    z_entry: float,
    z_floor: float,
    valley_radius: float,
) -> np.ndarray:
    """Vertices of one convex wedge of a square tile around a hole, with a sloping valley top.

    The wedge lies between the rays at ``angle0 < angle1`` (rad, about ``centre``, spanning less
    than pi) and inside the square of half-width ``half_width`` centred on the hole. Its inner
    boundary is the chord perpendicular to the bisector at distance ``r_hole`` from the centre
    (as :func:`~teachfit.tasks.scene.mjcf.ring_sector` does), so ``K`` wedges leave a polygonal hole
    that is never narrower than the circle of radius ``r_hole``.

    The top surface, with ``d`` the distance from the centre measured along the bisector, is
    ``z_entry`` at ``d = r_hole`` rising linearly to ``z_floor`` at ``d = valley_radius`` and
    flat beyond (``z_entry == z_floor`` gives a flat tile).

    Parameters
    ----------
    centre : (float, float)
        Hole centre in x-y (m, body frame).
    angle0, angle1 : float
        Bounding rays of the wedge (rad).
    r_hole : float
        Hole radius (m): distance of the inner chord from the centre.
    half_width : float
        Half side of the square tile (m).
    z_bottom, z_entry, z_floor : float
        Bottom of the piece (the hole's bottom), top at the hole edge, flat floor top (m).
    valley_radius : float
        Distance from the centre (along the bisector) where the valley meets the floor (m).

    Returns
    -------
    vertices : ndarray, shape (n, 3)
    """
    c = np.asarray(centre, dtype=float)
    half = (angle1 - angle0) / 2.0
    mid = angle0 + half
    u = np.array([np.cos(mid), np.sin(mid)])
    poly = _wedge_outline(c, angle0, angle1, r_hole / np.cos(half), half_width)

    def depth_along(p: np.ndarray) -> float:
        return float((p - c) @ u)

    crease = _crease(poly, depth_along, valley_radius) if z_floor > z_entry else []
    valley = (r_hole, z_entry, z_floor, valley_radius)
    verts = [(p[0], p[1], _valley_top(depth_along(p), *valley)) for p in poly]
    verts += [(p[0], p[1], z_floor) for p in crease]
    verts += [(p[0], p[1], z_bottom) for p in poly]
    return np.unique(np.round(np.asarray(verts), 12), axis=0)


def _valley_top(
    d: float, r_hole: float, z_entry: float, z_floor: float, valley_radius: float
) -> float:
    """Height (m) of the valley top at distance ``d`` (m) from the centre along the bisector:
    ``z_entry`` at ``r_hole`` rising linearly to ``z_floor`` at ``valley_radius``, flat beyond."""
    if z_floor <= z_entry or valley_radius <= r_hole:
        return z_floor
    slope = (z_floor - z_entry) / (valley_radius - r_hole)
    return min(z_floor, z_entry + slope * (d - r_hole))


def _wedge_outline(
    c: np.ndarray, angle0: float, angle1: float, inner: float, half_width: float
) -> list[np.ndarray]:
    """The wedge's x-y outline (m) in order: out along the ray at ``angle0`` from distance
    ``inner`` to the square's edge, the square's corners between the rays, back in along the
    ray at ``angle1``."""
    rays = [np.array([np.cos(a), np.sin(a)]) for a in (angle0, angle1)]
    poly = [c + inner * rays[0], c + _square_exit(rays[0], half_width) * rays[0]]
    for k in range(4):  # square corners strictly between the two rays
        corner_ang = np.pi / 4 + k * np.pi / 2
        rel = (corner_ang - angle0) % (2 * np.pi)
        if 1e-9 < rel < angle1 - angle0 - 1e-9:
            poly.append(
                c + half_width * np.sqrt(2.0) * np.array([np.cos(corner_ang), np.sin(corner_ang)])
            )
    poly += [c + _square_exit(rays[1], half_width) * rays[1], c + inner * rays[1]]
    return poly


def _crease(
    poly: list[np.ndarray], depth_along: Callable[[np.ndarray], float], valley_radius: float
) -> list[np.ndarray]:
    """Where the outline's edges cross ``depth_along == valley_radius`` (m): the points of the
    line where the valley plane meets the flat floor."""
    crease = []
    for a, b in zip(poly, poly[1:] + poly[:1], strict=True):
        da, db = depth_along(a) - valley_radius, depth_along(b) - valley_radius
        if da * db < 0:
            crease.append(a + (b - a) * da / (da - db))
    return crease


def disc_segment(
    radius: float,
    z_bottom: float,
    z_top: float,
    half_planes: list[tuple[float, float, float]],
    n_arc: int = 72,
) -> np.ndarray:
    """Vertices of a prism over ``{|p| <= radius} ∩ {a x + b y >= c for (a, b, c)}``.

    The arc is sampled with ``n_arc`` points per full turn (vertices on the circle, so the piece
    never reaches beyond ``radius``); the half-plane boundaries are exact.

    Parameters
    ----------
    radius : float
        Disc radius (m), centred on the body origin.
    z_bottom, z_top : float
        Bottom and top of the prism (m).
    half_planes : list of (a, b, c)
        Kept half-planes ``a x + b y >= c`` with unit ``(a, b)``.
    n_arc : int
        Arc samples per full turn.

    Returns
    -------
    vertices : ndarray, shape (n, 3)
    """
    ang = np.linspace(0.0, 2 * np.pi, n_arc, endpoint=False)
    pts = list(radius * np.stack([np.cos(ang), np.sin(ang)], axis=1))
    # exact intersections of each boundary line with the circle and with the other lines
    lines = [np.asarray(h, dtype=float) for h in half_planes]
    for a, b, cc in lines:
        n = np.array([a, b])
        foot = cc * n
        off = radius**2 - cc**2
        if off > 0:
            t = np.array([-b, a])
            pts += [foot + np.sqrt(off) * t, foot - np.sqrt(off) * t]
    for i, l1 in enumerate(lines):
        for l2 in lines[i + 1 :]:
            mat = np.array([l1[:2], l2[:2]])
            if abs(np.linalg.det(mat)) > 1e-12:
                pts.append(np.linalg.solve(mat, np.array([l1[2], l2[2]])))
    tol = 1e-12
    kept = [
        p
        for p in pts
        if p @ p <= radius**2 * (1 + 1e-9)
        and all(a * p[0] + b * p[1] >= cc - tol for a, b, cc in lines)
    ]
    verts = [(p[0], p[1], z) for p in kept for z in (z_bottom, z_top)]
    return np.unique(np.round(np.asarray(verts), 12), axis=0)


def rounded_pin(radius: float, length: float, tip_radius: float, n_sides: int = 16) -> np.ndarray:
    """Vertices of a cylinder along +z from ``z=0`` to ``length`` with a rounded tip edge.

    The tip edge is a quarter circle of radius ``tip_radius`` (sampled at 0, 45 and 90 degrees);
    vertices lie on the circles, so the pin is never wider than ``radius``.
    """
    ang = np.linspace(0.0, 2 * np.pi, n_sides, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    if tip_radius > 0:
        betas = np.linspace(0.0, np.pi / 2, 3)
        layers = [
            (radius - tip_radius * (1 - np.sin(b)), tip_radius * (1 - np.cos(b))) for b in betas
        ]
    else:
        layers = [(radius, 0.0)]
    layers.append((radius, length))
    verts = [np.column_stack([ring * r, np.full(n_sides, z)]) for r, z in layers]
    return np.concatenate(verts, axis=0)
