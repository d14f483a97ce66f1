"""Triangles of one shell that cross each other (a shell folding through itself).

Colliding a mesh's BVH with itself reports every pair of triangles that touch, and every
triangle touches its neighbours: a mesh of ``n`` triangles gave ~13 ``n`` contacts, and a fan
of ``k`` triangles around one vertex (a CAD cap) ``k**2``. Here each triangle is first shrunk
by :data:`SHRINK` of its size towards its centroid, in coordinates scaled to the part's size:
neighbours no longer touch, so coal's BVH traversal (the broad phase) reports only each
triangle against itself and the pairs that truly cross. Pairs that share a vertex are
dropped as before (a crossing confined to a shared vertex's neighbourhood is not a fold).
The work runs in slabs of :data:`CHUNK` triangles (sorted along the part's longest axis)
against the whole mesh, reported to :func:`teachfit.tasks.mesh.progress.report`. Measured
(CPU time, icospheres): 20 k triangles 0.5 s, 82 k 1.4 s, 328 k 5.7 s (the contacts of
every touching pair took 0.9, 6.2 and 58 s). A crossing confined to the outer 1 % of a
triangle is not seen. Long slivers fanning out of one vertex still overlap each other's
bounding volumes: a cylinder whose caps are fans of 8,000 triangles takes ~20 s.
"""

from __future__ import annotations

import coal
import numpy as np
import trimesh

from teachfit.tasks.mesh.progress import report

#: fraction of its size each triangle shrinks by towards its centroid
SHRINK = 1e-2
#: GJK tolerance in coordinates scaled to the part's size (well below the shrunk gaps)
GJK_TOLERANCE = 1e-10
#: triangles collided against the whole mesh per step
CHUNK = 20_000
#: crossing pairs looked for beyond the triangles' own (a count above says "at least")
MAX_PAIRS = 10_000


def _bvh(tris: np.ndarray) -> coal.BVHModelOBBRSS:
    """A BVH of the (k, 3, 3) triangles (each with its own three vertices)."""
    model = coal.BVHModelOBBRSS()
    model.beginModel(len(tris), 3 * len(tris))
    model.addVertices(np.ascontiguousarray(tris.reshape(-1, 3), dtype=float))
    model.addTriangles(np.arange(3 * len(tris), dtype=np.int64).reshape(-1, 3))
    model.endModel()
    return model


def _shrunk(mesh: trimesh.Trimesh) -> np.ndarray:
    """The mesh's triangles in its bounding box scaled to 1, each shrunk by :data:`SHRINK`."""
    tris = np.asarray(mesh.triangles, dtype=float)
    lo = tris.reshape(-1, 3).min(axis=0)
    size = float(np.ptp(tris.reshape(-1, 3), axis=0).max()) or 1.0
    tris = (tris - lo) / size
    centre = tris.mean(axis=1, keepdims=True)
    return centre + (tris - centre) * (1.0 - SHRINK)


def _touching(whole: coal.BVHModelOBBRSS, part: np.ndarray, first: int) -> np.ndarray:
    """(m, 2) index pairs ``(i, j)``, ``i`` among ``part`` (triangles ``first`` onwards),
    ``j`` in ``whole``, whose (shrunk) triangles touch, ``i != j``."""
    request = coal.CollisionRequest()
    request.num_max_contacts = len(part) + 2 * MAX_PAIRS
    request.gjk_tolerance = GJK_TOLERANCE
    result = coal.CollisionResult()
    eye = coal.Transform3s()
    coal.collide(_bvh(part), eye, whole, eye, request, result)
    pairs = np.array([(c.b1, c.b2) for c in result.getContacts()], dtype=np.int64)
    pairs = pairs.reshape(-1, 2) + np.array([first, 0], dtype=np.int64)
    return pairs[pairs[:, 0] != pairs[:, 1]]


def crossing_triangles(mesh: trimesh.Trimesh, what: str = "") -> tuple[int, np.ndarray] | None:
    """Pairs of triangles of ``mesh`` that cross without sharing a vertex: their number (at
    most :data:`MAX_PAIRS`) and a point near one crossing (m); None when there are none.

    ``what`` names the work in the progress reports (e.g. the mesh's file).
    """
    tris = _shrunk(mesh)
    centres = tris.mean(axis=1)
    order = np.argsort(centres[:, int(np.argmax(np.ptp(centres, axis=0)))], kind="stable")
    tris = tris[order]  # slabs along the longest axis: each step's BVH overlaps few others
    faces = np.asarray(mesh.faces, dtype=np.int64)[order]
    whole = _bvh(tris)
    steps = max(1, -(-len(tris) // CHUNK))
    found: list[np.ndarray] = []
    label = f"self-intersection check {what}".strip()
    for k in range(steps):
        lo = k * CHUNK
        found.append(_touching(whole, tris[lo : lo + CHUNK], lo))
        report(label, k + 1, steps)
    pairs = np.sort(np.concatenate(found), axis=1)
    a, b = faces[pairs[:, 0]], faces[pairs[:, 1]]
    crossing = pairs[~(a[:, :, None] == b[:, None, :]).any(axis=(1, 2))]
    if len(crossing) == 0:
        return None
    unique = np.unique(crossing, axis=0)
    at = np.asarray(mesh.triangles_center[order[unique[0]]], dtype=float).mean(axis=0)
    return min(len(unique), MAX_PAIRS), at
