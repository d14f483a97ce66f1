"""Convex prisms for polygonal holes and parts (triangle puzzle, key slot and wards).

MuJoCo collides a mesh as its convex hull, so a plate with a convex polygonal hole is built
from one piece per hole edge: the part of the plate's square outline *beyond* that edge's line,
``{p : n . p >= d}`` (outward unit normal ``n``, distance ``d`` of the edge from the hole
centre). Each piece is convex, the pieces overlap near the hole's corners (harmless: geoms of
one static body never collide with each other) and their union is exactly the square minus the
open polygon. An optional 45-degree chamfer lowers each piece's top linearly towards its edge;
that top is the minimum of two affine functions, so the solid under it stays convex.

Every builder returns vertex arrays (m, in the frame of the body the geom is attached to,
z up) whose convex hull is the intended solid.
"""

from __future__ import annotations

import numpy as np


def regular_polygon(n: int, inradius: float, phase: float = 0.0) -> np.ndarray:
    """Vertices (n, 2), counter-clockwise, of a regular ``n``-gon centred on the origin.

    Edge ``k`` has its outward normal at angle ``phase + 2 pi k / n`` and lies ``inradius``
    from the centre; the vertices are at ``inradius / cos(pi / n)``.
    """
    ang = phase + np.pi / n + 2 * np.pi * np.arange(n) / n
    r = inradius / np.cos(np.pi / n)
    return r * np.column_stack([np.cos(ang), np.sin(ang)])


def edge_normals(n: int, phase: float = 0.0) -> np.ndarray:
    """Outward unit normals (n, 2) of the edges of :func:`regular_polygon`."""
    ang = phase + 2 * np.pi * np.arange(n) / n
    return np.column_stack([np.cos(ang), np.sin(ang)])


def rectangle(half_x: float, half_y: float) -> np.ndarray:
    """Vertices (4, 2), counter-clockwise, of an axis-aligned rectangle centred on the origin."""
    return np.array([[half_x, half_y], [-half_x, half_y], [-half_x, -half_y], [half_x, -half_y]])


def clip_halfplane(poly: np.ndarray, normal: np.ndarray, offset: float) -> np.ndarray:
    """The convex polygon ``poly`` (k, 2) cut to ``{p : normal . p >= offset}``."""
    out: list[np.ndarray] = []
    k = len(poly)
    for i in range(k):
        a, b = poly[i], poly[(i + 1) % k]
        da, db = float(a @ normal) - offset, float(b @ normal) - offset
        if da >= 0:
            out.append(a)
        if da * db < 0:
            out.append(a + (b - a) * da / (da - db))
    return np.asarray(out)


def inset_polygon(poly: np.ndarray, distance: float) -> np.ndarray:
    """Move every edge of the convex counter-clockwise polygon ``poly`` inwards by ``distance``.

    The new vertices are the intersections of consecutive moved edge lines (valid while the
    inset keeps every edge, i.e. ``distance`` below the inradius).
    """
    k = len(poly)
    lines = []
    for i in range(k):
        a, b = poly[i], poly[(i + 1) % k]
        t = (b - a) / np.linalg.norm(b - a)
        n = np.array([t[1], -t[0]])  # outward for a counter-clockwise polygon
        lines.append((n, float(a @ n) - distance))
    out = []
    for i in range(k):
        (n1, c1), (n2, c2) = lines[i - 1], lines[i]
        out.append(np.linalg.solve(np.array([n1, n2]), np.array([c1, c2])))
    return np.asarray(out)


def beyond_edge_block(
    outline: np.ndarray,
    normal: np.ndarray,
    offset: float,
    z_bottom: float,
    z_top: float,
    chamfer: float = 0.0,
) -> np.ndarray:
    """Vertices of the part of the prism over ``outline`` that lies beyond one hole edge.

    Parameters
    ----------
    outline : ndarray, shape (k, 2)
        Convex counter-clockwise outline of the plate (m).
    normal : ndarray, shape (2,)
        Unit normal of the hole edge, pointing away from the hole centre.
    offset : float
        Distance of the hole edge from the hole centre (m); the piece is ``normal . p >= offset``.
    z_bottom, z_top : float
        Bottom and top of the piece (m).
    chamfer : float
        Width (= depth, 45 degrees) of the chamfer along the hole edge (m); 0 for a sharp edge.

    Returns
    -------
    vertices : ndarray, shape (n, 3)
    """
    n = np.asarray(normal, dtype=float)
    poly = clip_halfplane(np.asarray(outline, dtype=float), n, offset)
    if len(poly) < 3:
        raise ValueError("the hole edge lies outside the plate outline")

    def top(p: np.ndarray) -> float:
        return min(z_top, z_top - chamfer + float(p @ n) - offset) if chamfer > 0 else z_top

    verts = [(p[0], p[1], top(p)) for p in poly] + [(p[0], p[1], z_bottom) for p in poly]
    if chamfer > 0:  # the crease where the chamfer meets the flat top
        crease = clip_halfplane(poly, n, offset + chamfer)
        verts += [(p[0], p[1], z_top) for p in crease]
    return np.unique(np.round(np.asarray(verts), 12), axis=0)


def chamfered_prism(poly: np.ndarray, length: float, chamfer: float = 0.0) -> np.ndarray:
    """Vertices of a prism over ``poly`` along +z from ``z=0`` to ``length``, tip chamfered.

    With ``chamfer > 0`` the tip face at ``z=0`` is ``poly`` inset by ``chamfer`` and the
    full section is reached at ``z=chamfer`` (45 degrees on every edge).
    """
    poly = np.asarray(poly, dtype=float)
    layers = [(poly, length)]
    if chamfer > 0:
        layers += [(poly, chamfer), (inset_polygon(poly, chamfer), 0.0)]
    else:
        layers.append((poly, 0.0))
    verts = [np.column_stack([pts, np.full(len(pts), z)]) for pts, z in layers]
    return np.unique(np.round(np.concatenate(verts), 12), axis=0)


def chamfered_block(
    outline: np.ndarray,
    edges: list[tuple[np.ndarray, float]],
    z_bottom: float,
    z_top: float,
    chamfer: float,
) -> np.ndarray:
    """Vertices of the prism over ``outline`` with a 45-degree chamfer along several edges.

    Each edge ``(normal, offset)`` is a side of ``outline`` with its outward-into-material
    unit normal (the solid is ``normal . p >= offset`` there, as for
    :func:`beyond_edge_block`); its top is lowered to ``z_top - chamfer`` along that edge. The
    solid is the intersection of half-spaces (the outline's sides, bottom, top and one chamfer
    plane per edge), so it is convex; its vertices come from scipy's
    ``HalfspaceIntersection`` (Qhull), with the Chebyshev centre as the interior point.
    """
    from scipy.optimize import linprog
    from scipy.spatial import HalfspaceIntersection

    poly = np.asarray(outline, dtype=float)
    rows = []  # A x + b <= 0, x = (px, py, z)
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        t = (b - a) / np.linalg.norm(b - a)
        n = np.array([t[1], -t[0]])  # outward for a counter-clockwise outline
        rows.append([n[0], n[1], 0.0, -float(a @ n)])
    rows += [[0.0, 0.0, -1.0, z_bottom], [0.0, 0.0, 1.0, -z_top]]
    for normal, offset in edges:  # z <= z_top - chamfer + n . p - offset
        nx, ny = np.asarray(normal, dtype=float)
        rows.append([-nx, -ny, 1.0, -(z_top - chamfer) + offset])
    h = np.asarray(rows)
    norms = np.linalg.norm(h[:, :3], axis=1)
    lp = linprog(
        np.r_[0.0, 0.0, 0.0, -1.0],
        A_ub=np.column_stack([h[:, :3], norms]),
        b_ub=-h[:, 3],
        bounds=[(None, None)] * 3 + [(0.0, None)],
    )
    if not lp.success or lp.x[3] <= 0:
        raise ValueError("the chamfered block is empty (chamfer too large for its outline)")
    verts = HalfspaceIntersection(h, lp.x[:3]).intersections
    return np.unique(np.round(verts, 12), axis=0)
