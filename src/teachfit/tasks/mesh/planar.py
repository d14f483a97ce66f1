"""Exact convex decomposition of rectilinear parts (every face normal to a mesh axis) into boxes.

Why by hand: ``coacd`` bounds each piece's concavity relative to the part's size (at least
1 % of it, ~0.7 mm on a 70 mm plate), so around a 0.2 mm clearance its pieces' hulls cut the
hole's corners: measured on the shipped ``square-peg`` plate at every threshold from 0.05 to
0.01, the hole closes. Machined fixtures (plates with pockets, receptacles) are mostly
rectilinear, and for those an exact decomposition is simple: the planes of the faces split the
bounding box into a grid of cells, each wholly inside or outside the part (tested on the
part's cross-section at the cell's mid-height, :func:`teachfit.tasks.mesh.sections.section`),
and the inside cells merge greedily into as few boxes as that finds. The boxes' union is the
part exactly. Parts with slanted or curved faces return None and go to ``coacd``. The planes
are the faces' own (the inner vertices of a finely tessellated face add none), and a grid of
more than :data:`MAX_CELLS` cells goes to ``coacd`` too instead of filling memory.
"""

from __future__ import annotations

import numpy as np
import shapely
import trimesh

from teachfit.tasks.mesh.sections import section

#: coordinates closer than this fraction of the part's size are one grid plane
MERGE_TOL = 1e-7
#: most grid cells the exact decomposition tries
MAX_CELLS = 2_000_000


def _planes(coords: np.ndarray, tol: float) -> np.ndarray:
    values = np.sort(coords)
    keep = np.concatenate([[True], np.diff(values) > tol])
    return values[keep]


def is_rectilinear(mesh: trimesh.Trimesh) -> bool:
    """Whether every face of ``mesh`` is normal to its x, y or z axis."""
    n = np.abs(mesh.face_normals)
    return bool(np.all(np.isclose(n.max(axis=1), 1.0, atol=1e-9)))


def _occupancy(mesh: trimesh.Trimesh, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray) -> np.ndarray:
    xc, yc, zc = (xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2, (zs[:-1] + zs[1:]) / 2
    gx, gy = np.meshgrid(xc, yc, indexing="ij")
    occ = np.zeros((len(xc), len(yc), len(zc)), dtype=bool)
    for k, z in enumerate(zc):
        occ[:, :, k] = shapely.contains_xy(section(mesh, float(z)), gx, gy)
    return occ


def _greedy_boxes(occ: np.ndarray) -> list[tuple[int, int, int, int, int, int]]:
    """Index boxes ``(i0, i1, j0, j1, k0, k1)`` (half-open) covering the True cells once."""
    todo = occ.copy()
    boxes = []
    nx, ny, nz = occ.shape
    for i0, j0, k0 in zip(*np.nonzero(todo), strict=True):
        if not todo[i0, j0, k0]:
            continue
        i1 = i0 + 1
        while i1 < nx and todo[i1, j0, k0]:
            i1 += 1
        j1 = j0 + 1
        while j1 < ny and todo[i0:i1, j1, k0].all():
            j1 += 1
        k1 = k0 + 1
        while k1 < nz and todo[i0:i1, j0:j1, k1].all():
            k1 += 1
        todo[i0:i1, j0:j1, k0:k1] = False
        boxes.append((int(i0), int(i1), int(j0), int(j1), int(k0), int(k1)))
    return boxes


def box_pieces(mesh: trimesh.Trimesh, max_pieces: int) -> list[trimesh.Trimesh] | None:
    """Boxes whose union is the rectilinear ``mesh``; None for a part with other faces or
    more than ``max_pieces`` boxes."""
    if not is_rectilinear(mesh):
        return None
    tol = MERGE_TOL * float(np.ptp(mesh.vertices, axis=0).max())
    axis = np.abs(mesh.face_normals).argmax(axis=1)
    centres = mesh.triangles_center
    xs, ys, zs = (_planes(centres[axis == a, a], tol) for a in range(3))
    if min(len(xs), len(ys), len(zs)) < 2 or len(xs) * len(ys) * len(zs) > MAX_CELLS:
        return None
    boxes = _greedy_boxes(_occupancy(mesh, xs, ys, zs))
    if not boxes or len(boxes) > max_pieces:
        return None
    pieces = []
    for i0, i1, j0, j1, k0, k1 in boxes:
        lo = np.array([xs[i0], ys[j0], zs[k0]])
        hi = np.array([xs[i1], ys[j1], zs[k1]])
        pieces.append(trimesh.creation.box(bounds=np.stack([lo, hi])))
    covered = sum(float(p.volume) for p in pieces)
    if not np.isclose(covered, float(mesh.volume), rtol=1e-6):
        return None  # the grid missed a feature (should not happen for a rectilinear solid)
    return pieces
