"""Exact convex decomposition of parts whose only curved faces are round bores.

Why by hand: ``coacd`` bounds each piece's concavity relative to the part's size, so around a
0.1 mm per-side clearance its pieces close a round bore (0 % of the clearance kept with the
default settings on an 8.2 mm bore in a 9 mm plate). Machined fixtures are mostly a
rectilinear block with round bores (through or blind, with chamfers or countersinks), and for
those an exact decomposition is simple, as for the built-in round holes
(:func:`teachfit.tasks.scene.mjcf.ring_sector`):

* every connected surface of faces not normal to the bore axis (a mesh axis) that is not
  rectilinear must be a bore: its vertices lie, level by level along the axis, on circles
  about one common axis (within :data:`RADIAL_TOL`), at least :data:`MIN_SEGMENTS` around
  (a hexagonal or square pocket is no bore), with its faces looking at the axis;
* a square prism about each bore (as wide as the material around it allows) is cut into
  ``N`` angular sectors, each a convex prism between the bore's profile and the square,
  split along the axis where the profile ``r(z)`` stops being convex (a counterbore step);
* the rest of the part (the part minus the prisms) must be rectilinear and is cut into boxes
  (:mod:`.planar`).

Faceting: each sector's inner face is a chord whose *closest* point lies on the true circle
(radius ``r``, fitted to the mesh's vertices), so the polygonal bore circumscribes the circle
and never narrows the clearance (the mesh's own facets are inscribed chords, so the pieces
keep at least 100 % of the mesh's clearance). At the chord's ends the bore is wider than the
circle by ``r (sec(pi / N) - 1)``; :func:`sector_count` takes the smallest multiple of 8 with
``r (sec(pi / N) - 1) <= widening``, i.e. ``N >= pi / arccos(r / (r + widening))``, about
``pi sqrt(r / (2 widening))``. The default widening (0.02 mm,
:class:`~teachfit.tasks.mesh.decompose.CoacdSettings`) gives an 8.2 mm bore 32 sectors, as
many as the built-in ``peg2d`` hole: measured on the ``round-peg`` example, 0.01 mm (48 and
56 sectors) halved the simulation's speed in contact (each sector under the part is one more
contact) and 0.02 mm kept it above 0.5x ``peg2d``'s (``benchmarks/round_contact.py``).
Multiples of 8 put the square's corners on sector edges, so every sector meets one side of
the square only.
Parts with any other curved face return None and go to ``coacd``. Lengths in metres, in the
mesh's own frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import manifold3d
import numpy as np
import shapely
import trimesh

from teachfit.tasks.mesh.loading import from_manifold, to_manifold
from teachfit.tasks.mesh.planar import box_pieces
from teachfit.tasks.mesh.sections import section

#: most a bore's vertices may stray from its fitted circle (m)
RADIAL_TOL = 2e-6
#: fewest facets around a bore (its largest angular gap at most 360 / this degrees)
MIN_SEGMENTS = 16
#: most sectors per bore
MAX_SECTORS = 256
#: grid (m) the sides of the bores' prisms are rounded to
SNAP = 1e-8
#: largest half side of a bore's square of sectors, times the bore's radius (kept small: the
#: part beyond rests on a few boxes instead of on many thin sectors, fewer contacts)
SQUARE_CAP = 1.25
#: thinnest wall (fraction of the bore radius) a bore's square must leave around it
MIN_WALL = 0.05

Piece = tuple[np.ndarray, np.ndarray]


@dataclass(frozen=True)
class Bore:
    """A round bore about an axis parallel to z at ``centre`` (x, y), its profile the radii
    ``radii`` at the heights ``levels`` (ascending, m)."""

    centre: np.ndarray
    levels: np.ndarray
    radii: np.ndarray

    def radius_at(self, z: float) -> float:
        """The bore's radius at height ``z`` (m), linear between levels."""
        return float(np.interp(z, self.levels, self.radii))


def sector_count(radius: float, widening: float) -> int:
    """Smallest multiple of 8 (at least 16, at most :data:`MAX_SECTORS`) of sectors whose
    circumscribing polygon widens a circle of ``radius`` by at most ``widening`` (m) at its
    corners: ``radius * (sec(pi / N) - 1) <= widening``."""
    n = np.pi / np.arccos(radius / (radius + widening))
    return int(min(MAX_SECTORS, max(16, 8 * np.ceil(n / 8 - 1e-9))))


def _fit_circle(xy: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Centre, radius and largest radial deviation of the least-squares circle through ``xy``."""
    a = np.column_stack([2 * xy, np.ones(len(xy))])
    sol = np.linalg.lstsq(a, (xy**2).sum(axis=1), rcond=None)[0]
    c = sol[:2]
    r = float(np.sqrt(max(sol[2] + c @ c, 0.0)))
    return c, r, float(np.abs(np.linalg.norm(xy - c, axis=1) - r).max())


def _levels(z: np.ndarray, tol: float) -> list[np.ndarray]:
    """Indices of ``z`` grouped into levels closer than ``tol``, ascending."""
    order = np.argsort(z)
    cuts = np.nonzero(np.diff(z[order]) > tol)[0] + 1
    return np.split(order, cuts)


def _bore_of(mesh: trimesh.Trimesh, faces: np.ndarray) -> Bore | None:
    """The bore whose wall is the faces ``faces`` of ``mesh``, or None if they are no bore."""
    verts = mesh.vertices[np.unique(mesh.faces[faces])]
    fits = []
    for idx in _levels(verts[:, 2], RADIAL_TOL):
        if len(idx) < MIN_SEGMENTS:
            return None
        xy = verts[idx, :2]
        c, r, dev = _fit_circle(xy)
        ang = np.sort(np.arctan2(xy[:, 1] - c[1], xy[:, 0] - c[0]))
        gaps = np.diff(np.concatenate([ang, [ang[0] + 2 * np.pi]]))
        if dev > RADIAL_TOL or gaps.max() > 2 * np.pi / MIN_SEGMENTS + 1e-9:
            return None
        fits.append((float(verts[idx, 2].mean()), c, r))
    centres = np.array([c for _, c, _ in fits])
    if len(fits) < 2 or np.abs(centres - centres.mean(axis=0)).max() > RADIAL_TOL:
        return None
    centre = centres.mean(axis=0)
    n = mesh.face_normals[faces, :2]
    to_axis = centre - mesh.triangles_center[faces, :2]
    if np.any((n * to_axis).sum(axis=1) <= 0):
        return None  # a face looking away from the axis: a boss, not a bore
    return Bore(centre, np.array([z for z, _, _ in fits]), np.array([r for _, _, r in fits]))


def find_bores(mesh: trimesh.Trimesh) -> list[Bore] | None:
    """The round bores about axes parallel to z of ``mesh``; None where a surface of faces not
    normal to z is neither rectilinear nor a bore (see the module docstring)."""
    side = np.nonzero(np.abs(mesh.face_normals[:, 2]) < 1 - 1e-9)[0]
    if len(side) == 0:
        return []
    adj = mesh.face_adjacency
    keep = np.isin(adj, side).all(axis=1)
    bores = []
    for comp in trimesh.graph.connected_components(adj[keep], nodes=side):
        comp = np.asarray(comp)
        if np.all(np.isclose(np.abs(mesh.face_normals[comp, :2]).max(axis=1), 1.0, atol=1e-9)):
            continue  # rectilinear: left to the boxes
        bore = _bore_of(mesh, comp)
        if bore is None:
            return None
        bores.append(bore)
    return bores


def _slabs(bore: Bore) -> list[tuple[int, int]]:
    """Level index ranges ``(i, j)`` (inclusive) over which the profile ``r(z)`` is convex (its
    slope never decreases upward), so that each slab's sectors are convex."""
    z, r = bore.levels, bore.radii
    slope = np.diff(r) / np.diff(z)
    out, start = [], 0
    for k in range(1, len(slope)):
        if slope[k] < slope[k - 1] - 1e-9:
            out.append((start, k))
            start = k
    out.append((start, len(z) - 1))
    return out


def square(bore: Bore, half_side: float) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners (x, y; m) of the square of half side ``half_side`` about
    ``bore``, on a grid of :data:`SNAP` (two squares that touch share their side exactly)."""
    lo = np.round((bore.centre - half_side) / SNAP) * SNAP
    hi = np.round((bore.centre + half_side) / SNAP) * SNAP
    return lo, hi


def _exit(centre: np.ndarray, u: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """Distance from ``centre`` along the unit ``u`` to the side of the box ``lo``-``hi``."""
    with np.errstate(divide="ignore"):
        t = np.where(u > 0, (hi - centre) / u, np.where(u < 0, (lo - centre) / u, np.inf))
    return float(t.min())


def sector_pieces(bore: Bore, half_side: float, n: int) -> list[np.ndarray]:
    """Vertices of the ``n`` sectors per slab filling the :func:`square` prism of half side
    ``half_side`` about ``bore`` outside its circumscribing polygon (m)."""
    lo, hi = square(bore, half_side)
    out = []
    edges = 2 * np.pi * np.arange(n + 1) / n
    half = np.pi / n
    for i, j in _slabs(bore):
        zs, rs = bore.levels[i : j + 1], bore.radii[i : j + 1]
        for a0, a1 in zip(edges[:-1], edges[1:], strict=True):
            pts = []
            for a in (a0, a1):
                u = np.array([np.cos(a), np.sin(a)])
                far = _exit(bore.centre, u, lo, hi)
                pts += [
                    (*(bore.centre + u * r / np.cos(half)), z) for r, z in zip(rs, zs, strict=True)
                ]
                pts += [(*(bore.centre + u * far), z) for z in (zs[0], zs[-1])]
            out.append(np.asarray(pts, dtype=float))
    return out


def _bore_ring(sec: shapely.Geometry, bore: Bore, z: float) -> shapely.Polygon | None:
    """The void of ``sec`` (the section at ``z``) around the bore's axis, if it is the bore
    alone: every vertex within a facet's sag of the bore's radius there."""
    axis = shapely.Point(*bore.centre)
    r = bore.radius_at(z)
    for poly in getattr(sec, "geoms", [sec]):
        for ring in getattr(poly, "interiors", []):
            hole = shapely.Polygon(ring)
            if hole.contains(axis):
                d = np.linalg.norm(np.asarray(ring.coords)[:, :2] - bore.centre, axis=1)
                sag = r * (1 - np.cos(np.pi / MIN_SEGMENTS))
                ok = d.max() <= r + RADIAL_TOL and d.min() >= r - sag - RADIAL_TOL
                return hole if ok else None
    return None


def _heights(mesh: trimesh.Trimesh, bore: Bore) -> np.ndarray:
    """Mid-heights between the mesh's vertex levels within the bore's extent: within each
    band between them the sections change shape continuously, so these see every feature."""
    z = np.sort(mesh.vertices[:, 2])
    z = z[np.concatenate([[True], np.diff(z) > RADIAL_TOL])]  # one per level
    z0, z1 = bore.levels[0], bore.levels[-1]
    z = np.concatenate([[z0], z[(z > z0 + RADIAL_TOL) & (z < z1 - RADIAL_TOL)], [z1]])
    return (z[:-1] + z[1:]) / 2


def _room(mesh: trimesh.Trimesh, bore: Bore, n: int) -> float | None:
    """Half side (m) of the largest square prism about ``bore`` over its extent that is solid
    but for the bore (at most :data:`SQUARE_CAP` times its radius); None if the bore is not
    alone in it or the wall it leaves is thinner than :data:`MIN_WALL` of its radius."""
    r_max = float(bore.radii.max())
    filled, reach = [], SQUARE_CAP * r_max
    for z in _heights(mesh, bore):
        sec = section(mesh, float(z))
        hole = _bore_ring(sec, bore, float(z))
        if hole is None:
            return None
        solid = shapely.union(sec, hole)
        filled.append(solid)
        reach = min(reach, float(solid.boundary.distance(shapely.Point(*bore.centre))))

    def fits(s: float) -> bool:
        square = shapely.box(*(bore.centre - s * (1 - 1e-9)), *(bore.centre + s * (1 - 1e-9)))
        return all(f.contains(square) for f in filled)

    lo, hi = reach / np.sqrt(2), reach  # a square of half side reach / sqrt 2 always fits
    if fits(hi):
        lo = hi
    for _ in range(12):  # else the largest that fits, to 0.03 % of the reach
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if fits(mid) else (lo, mid)
    return lo if lo >= r_max / np.cos(np.pi / n) * (1 + MIN_WALL) else None


def _separate(bores: list[Bore], sides: list[float]) -> list[float]:
    """Shrink the squares of bores that overlap along z so that their prisms do not overlap."""
    sides = list(sides)
    for a in range(len(bores)):
        for b in range(a + 1, len(bores)):
            A, B = bores[a], bores[b]
            if A.levels[-1] <= B.levels[0] or B.levels[-1] <= A.levels[0]:
                continue
            gap = float(np.abs(A.centre - B.centre).max()) / 2
            sides[a], sides[b] = min(sides[a], gap), min(sides[b], gap)
    return sides


def _hull(verts: np.ndarray) -> Piece:
    hull = trimesh.Trimesh(verts).convex_hull
    return np.asarray(hull.vertices, dtype=float), np.asarray(hull.faces, dtype=np.int64)


def _prism(mesh: trimesh.Trimesh, bore: Bore, half_side: float) -> manifold3d.Manifold:
    """The square prism about ``bore`` over its extent, to cut from the part: through the
    part's top or bottom where the bore reaches it, else ending on the bore's level exactly
    as :func:`~teachfit.tasks.mesh.loading.to_manifold` rounds it (float32), its sides
    the :func:`square`'s: the cut leaves no sliver."""
    lo, hi = mesh.bounds[:, 2]
    margin = 0.01 * float(np.ptp(mesh.vertices, axis=0).max())
    z0, z1 = (float(np.float32(z)) for z in (bore.levels[0], bore.levels[-1]))
    z0 = z0 - margin if bore.levels[0] <= lo + RADIAL_TOL else z0
    z1 = z1 + margin if bore.levels[-1] >= hi - RADIAL_TOL else z1
    lo_xy, hi_xy = square(bore, half_side)
    size = [*(hi_xy - lo_xy), z1 - z0]
    return manifold3d.Manifold.cube(size).translate([*lo_xy, z0])


def _cut_z(mesh: trimesh.Trimesh, widening: float, max_boxes: int) -> list[Piece] | None:
    """The exact pieces of ``mesh`` whose bores run along z; None if it has other curves."""
    bores = find_bores(mesh)
    if not bores:
        return None
    counts = [sector_count(float(b.radii.max()), widening) for b in bores]
    rooms = [_room(mesh, b, n) for b, n in zip(bores, counts, strict=True)]
    if any(s is None for s in rooms):
        return None
    sides = _separate(bores, [s for s in rooms if s is not None])
    walls = [
        float(b.radii.max()) / np.cos(np.pi / n) * (1 + MIN_WALL)
        for b, n in zip(bores, counts, strict=True)
    ]
    if any(s < w for s, w in zip(sides, walls, strict=True)):
        return None
    prisms = [_prism(mesh, b, s) for b, s in zip(bores, sides, strict=True)]
    rest = to_manifold(mesh) - manifold3d.Manifold.batch_boolean(prisms, manifold3d.OpType.Add)
    pieces: list[Piece] = []
    if rest.volume() > 0:
        boxes = box_pieces(from_manifold(rest), max_boxes)
        if boxes is None:
            return None
        pieces += [(np.asarray(b.vertices), np.asarray(b.faces)) for b in boxes]
    for b, s, n in zip(bores, sides, counts, strict=True):
        pieces += [_hull(v) for v in sector_pieces(b, s, n)]
    return pieces if _volume_agrees(mesh, pieces, bores, counts) else None


def _volume_agrees(
    mesh: trimesh.Trimesh, pieces: list[Piece], bores: list[Bore], counts: list[int]
) -> bool:
    """Whether the pieces' volume is the mesh's less at most the bores' faceting: each bore's
    circumscribing polygon (``n r^2 tan(pi / n)`` per unit height) is larger than the mesh's
    inscribed one (at least :data:`MIN_SEGMENTS` sides) by less than their difference."""
    total = sum(trimesh.Trimesh(v, f).volume for v, f in pieces)
    slack = 0.0
    for b, n in zip(bores, counts, strict=True):
        r2, m = float(b.radii.max()) ** 2, MIN_SEGMENTS
        area = n * r2 * np.tan(np.pi / n) - m / 2 * r2 * np.sin(2 * np.pi / m)
        slack += area * float(b.levels[-1] - b.levels[0])
    excess = float(mesh.volume) - total
    return bool(-1e-7 * mesh.volume <= excess <= slack + 1e-7 * mesh.volume)


#: cyclic turns taking the z, x or y axis of a mesh to z (proper rotations: no mirroring)
_TO_Z = (
    np.eye(3),
    np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]),
    np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
)


def revolved_pieces(mesh: trimesh.Trimesh, widening: float, max_boxes: int) -> list[Piece] | None:
    """Exact convex pieces (vertices, faces; mesh frame, m) of a rectilinear part with round
    bores along one mesh axis: ring sectors widening each bore by at most ``widening`` (m) at
    their corners, and at most ``max_boxes`` boxes for the rest; None for any other part."""
    for turn in _TO_Z:
        T = np.eye(4)
        T[:3, :3] = turn
        turned = mesh.copy()
        turned.apply_transform(T)
        pieces = _cut_z(turned, widening, max_boxes)
        if pieces is not None:
            return [(v @ turn, f) for v, f in pieces]  # turn.T undoes turn: v @ turn
    return None
