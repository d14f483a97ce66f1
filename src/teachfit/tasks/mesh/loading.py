"""Loading a user's part mesh (STL, OBJ, PLY through ``trimesh``) and rejecting bad ones.

A mesh must be a closed solid a collision check can trust: readable, non-empty, watertight,
consistently wound, of positive volume, not made of shells that overlap each other (the
usual self-intersection of CAD exports: bodies exported without their union) and of a size
that fits its declared units (a 20 m peg is a mm mesh declared as m). Each failure is one
:class:`~teachfit.core.errors.TaskError` line naming the file and the fix.
"""

from __future__ import annotations

from pathlib import Path

import coal
import manifold3d
import numpy as np
import trimesh

from teachfit.core.atomic import atomic_write_bytes
from teachfit.core.errors import TaskError

#: file types accepted for part meshes
MESH_SUFFIXES = (".stl", ".obj", ".ply")
#: a part larger than this (m) along any axis is taken for a unit mistake
MAX_EXTENT = 1.0
#: a part smaller than this (m) along every axis is taken for a unit mistake
MIN_EXTENT = 0.001


def load_mesh(path: Path, scale: float, role: str, task_file: Path) -> trimesh.Trimesh:
    """The mesh at ``path`` with coordinates multiplied by ``scale`` (metres per unit).

    ``role`` (``"held"`` or ``"fixed"``) and ``task_file`` only word the errors.
    """
    where = f"{task_file} [{role}] mesh"
    if not path.is_file():
        raise TaskError(f"{where}: {path} does not exist; fix the path (relative to the task file)")
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise TaskError(f"{where}: {path} is not an STL, OBJ or PLY file")
    try:
        loaded = trimesh.load(path, force="mesh", process=True)
    except Exception as exc:  # trimesh raises many types for broken files
        raise TaskError(f"{where}: cannot read {path} ({type(exc).__name__}: {exc})") from exc
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise TaskError(f"{where}: {path} holds no triangles; export the part as a mesh")
    mesh = loaded.copy()
    mesh.apply_scale(scale)
    check_solid(mesh, f"{where} {path}")
    extent = float(np.ptp(mesh.vertices, axis=0).max())
    if extent > MAX_EXTENT:
        raise TaskError(
            f"{where}: {path} is {extent:.1f} m across at the declared units; a part that large "
            'is a unit mistake: set units ("mm" for a CAD mesh in millimetres)'
        )
    if extent < MIN_EXTENT:
        raise TaskError(
            f"{where}: {path} is {1e3 * extent:.3f} mm across at the declared units; set units "
            '("m" for a mesh in metres)'
        )
    return mesh


def check_solid(mesh: trimesh.Trimesh, where: str) -> None:
    """Raise :class:`TaskError` unless ``mesh`` is a closed, non-self-overlapping solid.

    Inverted meshes (all normals inward) are turned outward in place.
    """
    if not np.all(np.isfinite(mesh.vertices)):
        raise TaskError(f"{where}: non-finite vertex coordinates; re-export the part")
    if not mesh.is_watertight:
        open_edges = len(trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1))
        raise TaskError(
            f"{where}: not watertight ({max(open_edges, 1)} open edge(s)); export the part as a "
            "closed solid (or repair it, e.g. in CAD or with trimesh.repair)"
        )
    if not mesh.is_winding_consistent:
        raise TaskError(f"{where}: inconsistent triangle winding; repair the mesh's normals")
    if mesh.volume < 0:
        mesh.invert()
    if mesh.volume <= 0:
        raise TaskError(f"{where}: zero volume; export the part as a solid")
    bodies = mesh.split(only_watertight=False) if mesh.body_count > 1 else [mesh]
    if len(bodies) > 1:
        total = sum(abs(b.volume) for b in bodies)
        union = manifold3d.Manifold.batch_boolean(
            [to_manifold(b) for b in bodies], manifold3d.OpType.Add
        )
        if union.volume() < total * (1 - 1e-6):
            raise TaskError(
                f"{where}: self-intersecting ({len(bodies)} shells overlap by "
                f"{1e9 * (total - union.volume()):.1f} mm^3); export the union of the bodies"
            )
    for body in bodies:
        crossing = crossing_triangles(body)
        if crossing is not None:
            n, at = crossing
            raise TaskError(
                f"{where}: self-intersecting ({n} pair(s) of triangles of one shell cross each "
                f"other, e.g. at ({', '.join(f'{1e3 * v:.2f}' for v in at)}) mm); repair the "
                "fold in CAD and re-export the part"
            )


def crossing_triangles(mesh: trimesh.Trimesh) -> tuple[int, np.ndarray] | None:
    """Pairs of triangles of ``mesh`` that meet without sharing a vertex (a shell folding
    through itself), their number and one contact point (m); None when there are none.

    coal collides the mesh's BVH with itself (manifold3d accepts such a mesh as manifold:
    its check is topological); every triangle touches itself and its neighbours, so the
    contact budget covers those and the pairs that share a vertex are dropped.
    """
    model = coal.BVHModelOBBRSS()
    faces = np.asarray(mesh.faces, dtype=np.int64)
    model.beginModel(len(faces), len(mesh.vertices))
    verts = coal.StdVec_Vec3s()
    verts.extend(list(np.asarray(mesh.vertices, dtype=float)))
    tris = coal.StdVec_Triangle()
    tris.extend([coal.Triangle(int(a), int(b), int(c)) for a, b, c in faces])
    model.addSubModel(verts, tris)
    model.endModel()
    degree = np.bincount(faces.ravel(), minlength=len(mesh.vertices))
    request = coal.CollisionRequest()
    request.num_max_contacts = int(2 * degree[faces].sum() + 2 * len(faces) + 1000)
    result = coal.CollisionResult()
    eye = coal.Transform3s()
    coal.collide(model, eye, model, eye, request, result)
    contacts = result.getContacts()
    pairs = np.array([(c.b1, c.b2) for c in contacts], dtype=np.int64).reshape(-1, 2)
    a, b = faces[pairs[:, 0]], faces[pairs[:, 1]]
    crossing = ~(a[:, :, None] == b[:, None, :]).any(axis=(1, 2))
    if not crossing.any():
        return None
    first = int(np.flatnonzero(crossing)[0])
    return int(crossing.sum()) // 2, np.asarray(contacts[first].pos, dtype=float)


def to_manifold(mesh: trimesh.Trimesh) -> manifold3d.Manifold:
    """``mesh`` as a manifold3d solid (for exact booleans)."""
    m = manifold3d.Mesh(
        vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
        tri_verts=np.asarray(mesh.faces, dtype=np.uint32),
    )
    return manifold3d.Manifold(m)


def from_manifold(solid: manifold3d.Manifold) -> trimesh.Trimesh:
    """A manifold3d solid as a processed ``trimesh.Trimesh`` (same units)."""
    m = solid.to_mesh()
    return trimesh.Trimesh(
        vertices=np.asarray(m.vert_properties)[:, :3].astype(float),
        faces=np.asarray(m.tri_verts).astype(np.int64),
        process=True,
    )


def write_atomic(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (:func:`teachfit.core.atomic.atomic_write_bytes`)."""
    atomic_write_bytes(path, data)
