"""Loading a user's part meshes (STL, OBJ, PLY through ``trimesh``) and rejecting bad ones.

A mesh must be a closed solid a collision check can trust: within the size and triangle
bounds (:mod:`.budget`, checked before it is read), readable, non-empty, of a size that fits
its declared units (:mod:`.plausible`: a 20 m peg is a mm mesh declared as m; checked before
the solid checks, so a unit mistake is named as such), watertight, consistently wound, of
positive volume, not made of shells that overlap each other (the usual self-intersection of
CAD exports: bodies exported without their union) nor of one shell folding through itself
(:mod:`.crossing`). Each failure is one :class:`~teachfit.core.errors.TaskError` line naming
the file and the fix.
"""

from __future__ import annotations

from pathlib import Path

import manifold3d
import numpy as np
import trimesh

from teachfit.core.atomic import atomic_write_bytes
from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.budget import check_mesh_file, check_triangle_count
from teachfit.tasks.mesh.crossing import crossing_triangles
from teachfit.tasks.mesh.plausible import PartSize, check_sizes
from teachfit.tasks.mesh.progress import report
from teachfit.tasks.mesh.spec import UNITS

#: file types accepted for part meshes
MESH_SUFFIXES = (".stl", ".obj", ".ply")


def read_mesh(path: Path, where: str) -> trimesh.Trimesh:
    """The mesh at ``path`` in its own numbers (file units), within the :mod:`.budget`
    bounds; ``where`` starts the error messages."""
    if not path.is_file():
        raise TaskError(f"{where}: {path} does not exist; fix the path (relative to the task file)")
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise TaskError(f"{where}: {path} is not an STL, OBJ or PLY file")
    check_mesh_file(path, where)
    try:
        loaded = trimesh.load(path, force="mesh", process=True)
    except Exception as exc:  # trimesh raises many types for broken files
        raise TaskError(f"{where}: cannot read {path} ({type(exc).__name__}: {exc})") from exc
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise TaskError(f"{where}: {path} holds no triangles; export the part as a mesh")
    check_triangle_count(len(loaded.faces), path, where)
    if not np.all(np.isfinite(loaded.vertices)):
        raise TaskError(f"{where} {path}: non-finite vertex coordinates; re-export the part")
    return loaded.copy()


def load_parts(
    held: Path, fixed: Path, units: str, task_file: Path
) -> tuple[trimesh.Trimesh, trimesh.Trimesh]:
    """The held and the fixed part's meshes (m; coordinates times the ``units``' scale),
    read, checked for plausible sizes at ``units`` and then as solids (see the module
    docstring). ``task_file`` words the errors."""
    where = {role: f"{task_file} [{role}] mesh" for role in ("held", "fixed")}
    meshes = {"held": read_mesh(held, where["held"]), "fixed": read_mesh(fixed, where["fixed"])}
    paths = {"held": held, "fixed": fixed}
    sizes = [PartSize(r, paths[r], np.ptp(m.vertices, axis=0)) for r, m in meshes.items()]
    check_sizes(sizes, units, task_file)
    for role, mesh in meshes.items():
        mesh.apply_scale(UNITS[units])
        check_solid(mesh, f"{where[role]} {paths[role]}", paths[role].name)
    return meshes["held"], meshes["fixed"]


def check_solid(mesh: trimesh.Trimesh, where: str, name: str = "") -> None:
    """Raise :class:`TaskError` unless ``mesh`` is a closed, non-self-overlapping solid.

    Inverted meshes (all normals inward) are turned outward in place. ``name`` names the
    mesh in the progress reports.
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
        report(f"shell overlap check {name}".strip(), 0, 1)
        total = sum(abs(b.volume) for b in bodies)
        union = manifold3d.Manifold.batch_boolean(
            [to_manifold(b) for b in bodies], manifold3d.OpType.Add
        )
        report(f"shell overlap check {name}".strip(), 1, 1)
        if union.volume() < total * (1 - 1e-6):
            raise TaskError(
                f"{where}: self-intersecting ({len(bodies)} shells overlap by "
                f"{1e9 * (total - union.volume()):.1f} mm^3); export the union of the bodies"
            )
    for body in bodies:
        crossing = crossing_triangles(body, name)
        if crossing is not None:
            n, at = crossing
            raise TaskError(
                f"{where}: self-intersecting ({n} pair(s) of triangles of one shell cross each "
                f"other, e.g. at ({', '.join(f'{1e3 * v:.2f}' for v in at)}) mm); repair the "
                "fold in CAD and re-export the part"
            )


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
