"""Writing a new mesh task file from two meshes, and describing a mesh task's cell.

:func:`new_task_file` lists the fixed part's openings on every face
(:func:`~teachfit.tasks.mesh.holes.find_openings`) and takes the chosen one (by number, by a
point near its entry, else the one the held part fits with the least clearance) unless the
hole frame is given, builds the whole cell (every check, the decomposition, its fidelity) and
only then writes the file, atomically. :func:`describe` gives the rows ``teachfit tasks show``
prints.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.cell import DEFAULT_SUCCESS_SHARE, MeshCell, build_cell, grasp_of
from teachfit.tasks.mesh.holes import Opening, choose_opening, find_openings
from teachfit.tasks.mesh.loading import load_parts, write_atomic
from teachfit.tasks.mesh.spec import SEARCH_DIMS, UNITS, MeshTaskSpec, spec_to_toml
from teachfit.tasks.mesh.task import MeshTask, remember_cell

Vec3 = tuple[float, float, float]


@dataclass(frozen=True, eq=False)
class NewTask:
    """What :func:`new_task_file` wrote: the file, its cell, the openings it found (empty
    where the hole frame was given) and the chosen one's place among them."""

    path: Path
    cell: MeshCell
    openings: list[Opening]
    chosen: int | None


def _rounded(v: np.ndarray) -> Vec3:
    x, y, z = (float(round(float(c), 6)) + 0.0 for c in v)
    return (x, y, z)


def _choose(
    spec: MeshTaskSpec,
    parts: tuple[trimesh.Trimesh, trimesh.Trimesh],
    axis: Vec3 | None,
    hole: int | None,
    hole_at: Vec3 | None,
) -> tuple[MeshTaskSpec, list[Opening], int]:
    """``spec`` with the chosen opening's hole frame (the file's units), the openings (along
    ``axis`` only if given), the choice."""
    held, fixed = parts
    held_tcp = held.copy()
    held_tcp.apply_transform(grasp_of(spec, held))
    openings = find_openings(fixed, held_tcp, None if axis is None else np.asarray(axis))
    near = None if hole_at is None else np.asarray(hole_at) * spec.scale
    k = choose_opening(openings, hole, near)
    o = openings[k]
    x_axis = None if o.x_axis is None else _rounded(o.x_axis)
    pos, ax = _rounded(o.pos / spec.scale), _rounded(o.axis)
    spec = dataclasses.replace(spec, hole_pos=pos, insertion_axis=ax, hole_x_axis=x_axis)
    return spec, openings, k


def new_task_file(
    out: Path,
    held: Path,
    fixed: Path,
    units: str = "m",
    hole_pos: Vec3 | None = None,
    insertion_axis: Vec3 | None = None,
    search_dims: tuple[str, ...] = ("x", "y"),
    success_depth: float | None = None,
    rz_period_deg: float | None = None,
    overwrite: bool = False,
    hole: int | None = None,
    hole_at: Vec3 | None = None,
) -> NewTask:
    """Check the parts, infer or take the hole frame (``units``), write the task file ``out``.

    Without ``hole_pos`` the openings on every face (along ``insertion_axis`` only, if given)
    are listed and number ``hole`` (1-based), the one whose entry is nearest ``hole_at``
    (``units``) or the best fit is taken. ``success_depth`` and ``rz_period_deg`` left
    ``None`` are left out of the file: the cell derives them (see
    :mod:`teachfit.tasks.mesh.spec`). Mesh paths are stored relative to ``out``'s folder
    where they lie inside it.
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
    if hole_pos is not None and (hole is not None or hole_at is not None):
        raise TaskError("--hole and --hole-at choose among the openings found: drop --hole-pos")
    spec = MeshTaskSpec(
        path=out,
        held_mesh=Path(held).resolve(),
        fixed_mesh=Path(fixed).resolve(),
        units=units,
        label=out.stem,
        hole_pos=hole_pos,
        insertion_axis=insertion_axis or (0.0, 0.0, -1.0),
        search_dims=tuple(search_dims),
        success_depth=success_depth,
        rz_period_deg=rz_period_deg,
    )
    parts = load_parts(spec.held_mesh, spec.fixed_mesh, units, out)
    openings: list[Opening] = []
    chosen = None
    if hole_pos is None:
        spec, openings, chosen = _choose(spec, parts, insertion_axis, hole, hole_at)
    cell = build_cell(spec, parts)
    write_atomic(out, spec_to_toml(spec).encode())
    remember_cell(out, cell)
    return NewTask(out, cell, openings, chosen)


def stop_text(cell: MeshCell) -> str:
    """Where and why the aligned part stops, e.g. ``9.000 mm (on the table: a through hole)``."""
    stop, table = cell.fit.stop_depth, float(cell.hole2world.pos[2])
    if stop >= table - 1e-6:
        why = "on the table: a through hole"
    elif stop >= cell.fit.hole_depth - 1e-6:
        why = "at the hole's bottom"
    else:
        why = "a shoulder of the held part meets the fixed part"
    return f"{1e3 * stop:.3f} mm ({why})"


def success_text(task: MeshTask) -> str:
    """The success depth and where it comes from."""
    cell, depth = task.cell, f"{1e3 * task.success_depth:.3f} mm"
    if cell.spec.success_depth is not None or abs(task.success_depth - cell.success_depth) > 1e-9:
        return f"{depth} (set)"
    share = f"{100 * DEFAULT_SUCCESS_SHARE:.0f} %"
    if cell.fit.stop_depth <= cell.held_length:
        return f"{depth} (default: {share} of the {1e3 * cell.fit.stop_depth:.3f} mm stop depth)"
    return f"{depth} (default: {share} of the held part's {1e3 * cell.held_length:.3f} mm)"


#: the usual shape behind each inferred yaw period (deg)
_SHAPES = {0.0: "any yaw fits, e.g. round", 90.0: "e.g. square", 180.0: "e.g. rectangle"}


def yaw_text(cell: MeshCell) -> str:
    """The yaw period and where it comes from, e.g. ``90 deg (inferred, e.g. square)``."""
    period = cell.rz_period_deg
    value = "free" if period == 0 else f"{period:g} deg"
    if cell.spec.rz_period_deg is not None:
        return f"{value} (set: rz_period_deg)"
    shape = _SHAPES.get(round(period, 6), "no symmetry" if period == 360 else "")
    return f"{value} (inferred from the sections{', ' + shape if shape else ''})"


def _vec(v: Vec3 | None) -> str:
    return "inferred" if v is None else "(" + ", ".join(f"{c:g}" for c in v) + ")"


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
        (
            "hole entry (fixed mesh)",
            f"{_vec(spec.hole_pos)} {spec.units}, insertion axis {_vec(spec.insertion_axis)}",
        ),
        ("hole entry (world)", " ".join(f"{1e3 * v:.2f}" for v in cell.hole2world.pos) + " mm"),
        ("hole depth", mm(cell.fit.hole_depth)),
        ("aligned part stops at", stop_text(cell)),
        ("success depth", success_text(task)),
        ("clearance per side", mm(cell.fit.clearance)),
        ("yaw tolerance", f"{np.degrees(cell.fit.rz_tolerance):.2f} deg"),
        ("yaw period", yaw_text(cell)),
        ("detection radius", mm(cell.fit.detection_radius)),
        ("search dims", ", ".join(task.search_dims)),
    ]
    for role, d in (("held", cell.held_pieces), ("fixed", cell.fixed_pieces)):
        how = "from cache" if d.cached else f"{d.seconds:.2f} s"
        rows.append((f"{role} pieces", f"{d.n_pieces} ({d.method}, {how})"))
    rows.append(("decomposition fidelity", cell.fidelity.summary()))
    return rows
