"""Writing a new mesh task file from two meshes, and describing a mesh task's cell.

:func:`new_task_file` infers the hole frame where it can (the opening in the fixed part's top
face the held part fits best, :func:`~teachfit.tasks.mesh.sections.infer_hole`) or takes it,
builds the whole cell (every check, the decomposition, its fidelity) and only then writes
the file, atomically. :func:`describe` gives the rows ``teachfit tasks show`` prints.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.cell import MeshCell, build_cell, grasp_of
from teachfit.tasks.mesh.loading import load_parts, write_atomic
from teachfit.tasks.mesh.sections import infer_hole
from teachfit.tasks.mesh.spec import SEARCH_DIMS, UNITS, MeshTaskSpec, spec_to_toml
from teachfit.tasks.mesh.task import MeshTask, remember_cell


def new_task_file(
    out: Path,
    held: Path,
    fixed: Path,
    units: str = "m",
    hole_pos: tuple[float, float, float] | None = None,
    insertion_axis: tuple[float, float, float] = (0.0, 0.0, -1.0),
    search_dims: tuple[str, ...] = ("x", "y"),
    success_depth: float | None = None,
    rz_period_deg: float = 0.0,
    overwrite: bool = False,
) -> tuple[Path, MeshCell]:
    """Check the parts, infer or take the hole frame (``units``), write the task file ``out``.

    Mesh paths are stored relative to ``out``'s folder where they lie inside it.
    """
    out = Path(out)
    if out.suffix != ".toml":
        raise TaskError(f"{out}: a task file must end in .toml")
    if out.exists() and not overwrite:
        raise TaskError(f"{out} exists; pass --overwrite to replace it")
    if units not in UNITS:
        raise TaskError(f"--units must be one of {sorted(UNITS)}, got {units!r}")
    if tuple(search_dims) not in SEARCH_DIMS:
        raise TaskError(f"--search-dims must be one of {SEARCH_DIMS}, got {search_dims}")
    spec = MeshTaskSpec(
        path=out,
        held_mesh=Path(held).resolve(),
        fixed_mesh=Path(fixed).resolve(),
        units=units,
        label=out.stem,
        hole_pos=hole_pos,
        insertion_axis=insertion_axis,
        search_dims=tuple(search_dims),
        success_depth=success_depth,
        rz_period_deg=rz_period_deg,
    )
    parts = load_parts(spec.held_mesh, spec.fixed_mesh, units, out)
    if hole_pos is None:
        scale = UNITS[units]
        h, f = parts
        if not np.allclose(insertion_axis, (0.0, 0.0, -1.0)):
            raise TaskError("the hole frame is inferred along -z only; give --hole-pos")
        held_tcp = h.copy()
        held_tcp.apply_transform(grasp_of(spec, h))
        pos = infer_hole(f, held_tcp) / scale
        x, y, z = (float(round(v, 6)) + 0.0 for v in pos)
        spec = dataclasses.replace(spec, hole_pos=(x, y, z))
    cell = build_cell(spec, parts)
    write_atomic(out, spec_to_toml(spec).encode())
    remember_cell(out, cell)
    return out, cell


def describe(task: MeshTask) -> list[tuple[str, str]]:
    """``(what, value)`` rows of a mesh task: meshes, hole frame, fit, pieces, fidelity."""
    cell, spec = task.cell, task.cell.spec

    def mm(x: float) -> str:
        return f"{1e3 * x:.3f} mm"

    rows = [
        ("task file", str(spec.path)),
        ("units", spec.units),
        ("held mesh", f"{spec.held_mesh} ({len(cell.held.faces)} triangles)"),
        ("fixed mesh", f"{spec.fixed_mesh} ({len(cell.fixed.faces)} triangles)"),
        ("held part size", " x ".join(f"{1e3 * e:.1f}" for e in cell.held.extents) + " mm"),
        ("fixed part size", " x ".join(f"{1e3 * e:.1f}" for e in cell.fixed.extents) + " mm"),
        ("hole entry (world)", " ".join(f"{1e3 * v:.2f}" for v in cell.hole2world.pos) + " mm"),
        ("hole depth", mm(cell.fit.hole_depth)),
        ("success depth", mm(task.success_depth)),
        ("clearance per side", mm(cell.fit.clearance)),
        ("yaw tolerance", f"{np.degrees(cell.fit.rz_tolerance):.2f} deg"),
        ("detection radius", mm(cell.fit.detection_radius)),
        ("search dims", ", ".join(task.search_dims)),
    ]
    for role, d in (("held", cell.held_pieces), ("fixed", cell.fixed_pieces)):
        how = "from cache" if d.cached else f"{d.seconds:.2f} s"
        rows.append((f"{role} pieces", f"{d.n_pieces} ({d.method}, {how})"))
    rows.append(("decomposition fidelity", cell.fidelity.summary()))
    return rows
