"""The openings of the fixed part, on any of its faces: found, listed and chosen.

Faces: every plane of the fixed mesh that carries at least 1 % of its area (triangles grouped
by outward normal, to 1e-4, and offset, to 1 um; the 32 largest) and the six faces of its
bounding box. On each, the section :data:`~teachfit.tasks.mesh.sections.ENTRY_EPS` inside the
face, in the frame :func:`~teachfit.tasks.mesh.cell.hole_frame` gives for an insertion against
the face's normal, has interior rings; a ring is an opening when the section as far outside
the face does not cover its centroid (it opens onto the face). Its entry centre is that
centroid on the face. The held part's footprint (its first 2 mm, TCP frame) placed there fits
when the ring contains it, unturned or turned 90 degrees (then the hole frame's x is the face
frame's y); its gap is the ring's distance to it. One opening per hole axis: of the openings
on one line (a through hole seen from both faces), the one the part fits best is kept, else
the first in the face order +z, +x, +y, -x, -y, -z (outward normal). Lengths in metres, in
the fixed mesh's frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
import trimesh
from shapely import affinity
from shapely.geometry.base import BaseGeometry

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.sections import ENTRY_EPS, footprint, section

#: outward face normals in the order openings are listed (others after them)
FACE_ORDER = np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0, 0, -1]])
#: the least share of the mesh's area a face plane carries to be searched, and how many
MIN_FACE_SHARE, MAX_FACES = 0.01, 32


@dataclass(frozen=True, eq=False)
class Opening:
    """One opening: entry centre ``pos`` (3,), insertion direction ``axis`` (3,, unit), the
    hole frame's x ``x_axis`` where the part fits only turned 90 degrees (else ``None``: the
    default), the opening's extents ``size`` along the hole frame's x and y, and ``gap``: the
    aligned part's clearance per side, ``None`` where it does not fit (m)."""

    pos: np.ndarray
    axis: np.ndarray
    x_axis: np.ndarray | None
    size: tuple[float, float]
    gap: float | None

    def line(self, scale: float, units: str) -> str:
        """One line about this opening, lengths in ``units`` (``scale`` metres each)."""

        def num(v: float) -> str:
            return f"{round(v / scale, 6) + 0.0:g}"

        pos = ", ".join(num(v) for v in self.pos)
        axis = ", ".join(f"{round(float(v), 4) + 0.0:g}" for v in self.axis)
        size = f"{num(self.size[0])} x {num(self.size[1])} {units}"
        fit = "too small" if self.gap is None else f"{num(self.gap)} {units} per side"
        return f"entry ({pos}) {units}, insertion axis ({axis}), opening {size}, fit: {fit}"


def _rotation(normal: np.ndarray) -> np.ndarray:
    """(3, 3) columns x, y, z of the frame whose z is ``normal``, x the mesh's x (else y) made
    normal to it: :func:`~teachfit.tasks.mesh.cell.hole_frame`'s rule."""
    x = np.array([1.0, 0.0, 0.0]) - normal * normal[0]
    if np.linalg.norm(x) < 1e-6:
        x = np.array([0.0, 1.0, 0.0]) - normal * normal[1]
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(normal, x), normal])


def face_planes(fixed: trimesh.Trimesh) -> list[tuple[np.ndarray, float]]:
    """``(outward normal, offset)`` of the planes searched for openings (module docstring)."""
    normals = fixed.face_normals
    offsets = np.einsum("ij,ij->i", normals, fixed.triangles_center)
    keys = np.column_stack([np.round(normals, 4), np.round(offsets, 6)])
    uniq, inv = np.unique(keys, axis=0, return_inverse=True)
    area = np.bincount(inv.ravel(), weights=fixed.area_faces, minlength=len(uniq))
    big = [i for i in np.argsort(-area, kind="stable") if area[i] >= MIN_FACE_SHARE * fixed.area]
    planes = [(uniq[i, :3] / np.linalg.norm(uniq[i, :3]), float(uniq[i, 3])) for i in big]
    planes = planes[:MAX_FACES]
    lo, hi = fixed.bounds
    for n in FACE_ORDER.astype(float):
        off = float(max(n @ lo, n @ hi))
        if not any(float(n @ m) > 0.9999 and abs(off - o) < 1e-6 for m, o in planes):
            planes.append((n, off))
    return planes


def _fit(ring: BaseGeometry, foot: BaseGeometry) -> tuple[float | None, bool]:
    """The gap of ``foot`` centred in the opening ``ring`` and whether it fits only turned."""
    c = ring.centroid
    for turned in (False, True):
        f = affinity.rotate(foot, 90.0, origin=(0, 0)) if turned else foot
        placed = affinity.translate(f, c.x, c.y)
        if ring.contains(placed):
            return float(ring.exterior.distance(placed)), turned
    return None, False


def _on_face(
    fixed: trimesh.Trimesh, normal: np.ndarray, offset: float, foot: BaseGeometry
) -> list[Opening]:
    R = _rotation(normal)
    T = np.eye(4)
    T[:3, :3] = R.T
    moved = fixed.copy()
    moved.apply_transform(T)
    inside, outside = section(moved, offset - ENTRY_EPS), section(moved, offset + ENTRY_EPS)
    out = []
    for poly in getattr(inside, "geoms", [inside]):
        for interior in getattr(poly, "interiors", []):
            ring = shapely.Polygon(interior)
            c = ring.centroid
            if outside.contains(c):
                continue
            gap, turned = _fit(ring, foot)
            x0, y0, x1, y1 = ring.bounds
            size = (y1 - y0, x1 - x0) if turned else (x1 - x0, y1 - y0)
            pos = R @ np.array([c.x, c.y, offset])
            x_axis = R[:, 1].copy() if turned else None
            out.append(Opening(pos, -normal.copy(), x_axis, (size[0], size[1]), gap))
    return out


def _order(o: Opening) -> tuple[float, ...]:
    hits = [i for i, n in enumerate(FACE_ORDER) if float(-o.axis @ n) > 0.9999]
    return (hits[0] if hits else len(FACE_ORDER), *np.round(o.pos, 6))


def _same_line(a: Opening, b: Opening) -> bool:
    if abs(float(a.axis @ b.axis)) < 0.9999:
        return False
    d = b.pos - a.pos
    return float(np.linalg.norm(d - a.axis * float(d @ a.axis))) < 1e-5


def find_openings(
    fixed: trimesh.Trimesh, held: trimesh.Trimesh, axis: np.ndarray | None = None
) -> list[Opening]:
    """The openings of ``fixed`` (mesh frame) for ``held`` (TCP frame), one per hole axis, in
    list order (module docstring); only those along the insertion ``axis`` if given."""
    foot = footprint(held, 0.002)
    found: list[Opening] = []
    for normal, offset in face_planes(fixed):
        if axis is not None and float(-normal @ axis) < 0.9999 * float(np.linalg.norm(axis)):
            continue
        found += _on_face(fixed, normal, offset, foot)
    kept: list[Opening] = []
    for o in sorted(found, key=lambda o: (o.gap is None, round(o.gap or 0.0, 7), _order(o))):
        if not any(_same_line(o, k) for k in kept):
            kept.append(o)
    return sorted(kept, key=_order)


def choose_opening(
    openings: list[Opening], index: int | None = None, near: np.ndarray | None = None
) -> int:
    """The chosen opening's place in ``openings``: number ``index`` (1-based), else the one
    whose entry is nearest the point ``near`` (m), else the one the held part fits with the
    least clearance (the first of equals). Errors name the option (``--hole``, ``--hole-at``)."""
    n = len(openings)
    if index is not None and near is not None:
        raise TaskError("give --hole or --hole-at, not both")
    if n == 0:
        raise TaskError(
            "no opening found on any face of the fixed part; give the hole frame "
            "(--hole-pos, --insertion-axis)"
        )
    if index is not None:
        if not 1 <= index <= n:
            raise TaskError(f"--hole {index}: the fixed part has {n} opening(s); choose 1 to {n}")
        k, what = index - 1, f"--hole {index}"
    elif near is not None:
        k = int(np.argmin([np.linalg.norm(o.pos - near) for o in openings]))
        what = f"--hole-at: the nearest opening, number {k + 1},"
    else:
        fits = [i for i, o in enumerate(openings) if o.gap is not None]
        if not fits:
            raise TaskError(
                f"none of the fixed part's {n} opening(s) fits the held part; check the meshes "
                "and units, or give the hole frame (--hole-pos, --insertion-axis)"
            )
        return min(fits, key=lambda i: (round(openings[i].gap or 0.0, 7), i))
    if openings[k].gap is None:
        raise TaskError(f"{what} is too small for the held part; choose another (1 to {n})")
    return k


def best_opening(fixed: trimesh.Trimesh, held: trimesh.Trimesh, axis: np.ndarray) -> Opening:
    """The opening along the insertion ``axis`` the held part fits with the least clearance."""
    openings = find_openings(fixed, held, axis)
    return openings[choose_opening(openings)]


def infer_hole(fixed: trimesh.Trimesh, held: trimesh.Trimesh) -> np.ndarray:
    """The entry centre (3,) of the best opening for an insertion along -z (m)."""
    return best_opening(fixed, held, np.array([0.0, 0.0, -1.0])).pos
