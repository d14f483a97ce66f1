"""The mesh task file: a TOML document naming a user's held and fixed part meshes.

Defaults worth knowing: without ``hole_pos`` the hole is the opening along ``insertion_axis``
that the held part fits with the least clearance (:mod:`teachfit.tasks.mesh.holes`); without
``success_depth`` it is 60 % of the depth where the aligned part stops (the hole's bottom, the
table under a through hole, or a shoulder of the held part; at most 60 % of the held part's
length); without ``rz_period_deg`` the yaw period is inferred from the cross-sections
(:func:`~teachfit.tasks.mesh.sections.rz_period_of`: 0 where any yaw fits, e.g. round; 180
for a rectangle; 90 for a square; 360 for no symmetry). ``teachfit tasks show`` says which.

Every length in the file, and every mesh coordinate, is in the file's ``units`` (``"m"``,
``"mm"``, ``"cm"`` or ``"in"``); angles are in degrees. Relative mesh paths resolve against
the task file's folder. Layout (all but the two meshes optional)::

    task = "mesh"
    units = "mm"
    [held]                        # the part the robot holds
    mesh = "peg.stl"
    grasp_pos = [0, 0, 0]         # the held mesh's frame in the tool (TCP) frame
    grasp_rpy_deg = [0, 0, 0]     #   (default: TCP at the centre of the mesh's lowest face)
    [fixed]                       # the part with the hole, standing on the table
    mesh = "board.stl"
    hole_pos = [0, 0, 15]         # hole entry centre in the fixed mesh's frame
    insertion_axis = [0, 0, -1]   # direction the part moves into the hole
    hole_x_axis = [1, 0, 0]       # hole frame x (the yaw reference); default: the mesh's x
    [params]
    success_depth = 5             # insertion past the entry that counts
    search_dims = ["x", "y"]      # or ["x", "y", "rz"]
    rz_period_deg = 90            # the held part's symmetry about its axis (0: any yaw fits)
    friction = 0.3
    [protocol]                    # start distributions (see MeshParams)
    demo_offset = 4
    [decomposition]               # coacd settings (see decompose.CoacdSettings)
    threshold = 0.03

:func:`read_spec` checks every key and names the file and the key in its one-line errors;
:func:`spec_to_toml` writes the same layout back.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

from teachfit.core.errors import TaskError

#: metres per unit of each accepted ``units`` value
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}
SEARCH_DIMS = (("x", "y"), ("x", "y", "rz"))
#: [protocol] keys: lengths in the file's units, ``*_deg`` in degrees; names of MeshParams
PROTOCOL_KEYS = (
    "demo_offset",
    "approach_height",
    "start_offset",
    "start_yaw_deg",
    "hole_pos_sigma",
    "hole_yaw_sigma_deg",
    "table1_radius",
)
DECOMPOSITION_KEYS = (
    "method",
    "threshold",
    "max_pieces",
    "resolution",
    "mcts_iterations",
    "seed",
    "widening",
)


@dataclass(frozen=True)
class MeshTaskSpec:
    """A parsed task file; lengths in ``units`` (``scale`` metres each), angles in degrees."""

    path: Path
    held_mesh: Path
    fixed_mesh: Path
    units: str = "m"
    label: str = ""
    grasp_pos: tuple[float, float, float] | None = None
    grasp_rpy_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    hole_pos: tuple[float, float, float] | None = None
    insertion_axis: tuple[float, float, float] = (0.0, 0.0, -1.0)
    hole_x_axis: tuple[float, float, float] | None = None
    success_depth: float | None = None
    search_dims: tuple[str, ...] = ("x", "y")
    rz_period_deg: float | None = None
    friction: float = 0.3
    protocol: dict[str, float] = field(default_factory=dict)
    decomposition: dict[str, float | str] = field(default_factory=dict)

    @property
    def scale(self) -> float:
        """Metres per unit of this file."""
        return UNITS[self.units]


def _fail(path: Path, message: str) -> TaskError:
    return TaskError(f"{path}: {message}")


def _vec(path: Path, table: dict[str, Any], key: str, where: str) -> tuple[float, float, float]:
    value = table[key]
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise _fail(path, f"[{where}] {key} must be three numbers, got {value!r}")
    return (float(arr[0]), float(arr[1]), float(arr[2]))


def _num(path: Path, table: dict[str, Any], key: str, where: str) -> float:
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
        raise _fail(path, f"[{where}] {key} must be a number, got {value!r}")
    return float(value)


def _only(path: Path, table: dict[str, Any], known: tuple[str, ...], where: str) -> None:
    unknown = sorted(set(table) - set(known))
    if unknown:
        raise _fail(path, f"unknown key(s) {unknown} in [{where}]; known: {sorted(known)}")


def _mesh_path(path: Path, table: dict[str, Any], where: str) -> Path:
    name = table.get("mesh")
    if not isinstance(name, str) or not name:
        raise _fail(path, f'[{where}] needs mesh = "FILE" (STL, OBJ or PLY)')
    mesh = Path(name)
    return mesh if mesh.is_absolute() else path.parent / mesh


def read_spec(path: str | Path) -> MeshTaskSpec:
    """Parse and check the task file ``path`` (see the module docstring for its layout)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise _fail(path, f"cannot read the task file ({exc.strerror or exc})") from exc
    except UnicodeDecodeError as exc:
        raise _fail(path, f"not a text (TOML) file ({exc.reason})") from exc
    except tomllib.TOMLDecodeError as exc:
        raise _fail(path, f"not valid TOML ({exc})") from exc
    top = ("task", "units", "name", "held", "fixed", "params", "protocol", "decomposition")
    _only(path, data, top, "top level")
    if data.get("task") != "mesh":
        raise _fail(path, f'task must be "mesh" for a mesh task, got {data.get("task")!r}')
    units = data.get("units", "m")
    if units not in UNITS:
        raise _fail(path, f"units must be one of {sorted(UNITS)}, got {units!r}")
    held, fixed = data.get("held"), data.get("fixed")
    if not isinstance(held, dict) or not isinstance(fixed, dict):
        raise _fail(path, 'needs a [held] and a [fixed] table, each with mesh = "FILE"')
    _only(path, held, ("mesh", "grasp_pos", "grasp_rpy_deg"), "held")
    _only(path, fixed, ("mesh", "hole_pos", "insertion_axis", "hole_x_axis"), "fixed")
    kw: dict[str, Any] = {}
    for key in ("grasp_pos", "grasp_rpy_deg"):
        if key in held:
            kw[key] = _vec(path, held, key, "held")
    for key in ("hole_pos", "insertion_axis", "hole_x_axis"):
        if key in fixed:
            kw[key] = _vec(path, fixed, key, "fixed")
    params = data.get("params", {})
    _only(path, params, ("success_depth", "search_dims", "rz_period_deg", "friction"), "params")
    for key in ("success_depth", "rz_period_deg", "friction"):
        if key in params:
            kw[key] = _num(path, params, key, "params")
    if not 0 <= kw.get("rz_period_deg", 0.0) <= 360:
        raise _fail(path, "[params] rz_period_deg must be within 0 (any yaw fits) .. 360 deg")
    if "search_dims" in params:
        dims = tuple(params["search_dims"])
        if dims not in SEARCH_DIMS:
            raise _fail(path, f"[params] search_dims must be one of {SEARCH_DIMS}, got {dims}")
        kw["search_dims"] = dims
    for where, known in (("protocol", PROTOCOL_KEYS), ("decomposition", DECOMPOSITION_KEYS)):
        table = data.get(where, {})
        _only(path, table, known, where)
        kw[where] = {
            k: str(v) if k == "method" else _num(path, table, k, where) for k, v in table.items()
        }
    label = data.get("name", path.stem)
    return MeshTaskSpec(
        path=path,
        held_mesh=_mesh_path(path, held, "held"),
        fixed_mesh=_mesh_path(path, fixed, "fixed"),
        units=units,
        label=str(label),
        **kw,
    )


def _toml_value(value: Any) -> str:
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, tuple | list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return f"{float(value):.9g}" if isinstance(value, float) else str(value)


def spec_to_toml(spec: MeshTaskSpec) -> str:
    """The TOML text of ``spec``; mesh paths relative to the task file's folder if inside it."""

    def rel(p: Path) -> str:
        try:
            return str(p.resolve().relative_to(spec.path.resolve().parent))
        except ValueError:
            return str(p.resolve())

    lines = [
        "# teachfit mesh task: lengths in the units below, angles in degrees",
        'task = "mesh"',
        f"name = {_toml_value(spec.label)}",
        f"units = {_toml_value(spec.units)}",
        "",
        "[held]",
        f"mesh = {_toml_value(rel(spec.held_mesh))}",
    ]
    if spec.grasp_pos is not None:
        lines.append(f"grasp_pos = {_toml_value(spec.grasp_pos)}")
    lines += [f"grasp_rpy_deg = {_toml_value(spec.grasp_rpy_deg)}", "", "[fixed]"]
    lines.append(f"mesh = {_toml_value(rel(spec.fixed_mesh))}")
    for f in fields(spec):
        if f.name in ("hole_pos", "insertion_axis", "hole_x_axis"):
            value = getattr(spec, f.name)
            if value is not None:
                lines.append(f"{f.name} = {_toml_value(value)}")
    lines += ["", "[params]"]
    if spec.success_depth is not None:
        lines.append(f"success_depth = {_toml_value(spec.success_depth)}")
    lines.append(f"search_dims = {_toml_value(list(spec.search_dims))}")
    if spec.rz_period_deg is not None:
        lines.append(f"rz_period_deg = {_toml_value(spec.rz_period_deg)}")
    lines.append(f"friction = {_toml_value(spec.friction)}")
    for where in ("protocol", "decomposition"):
        table = getattr(spec, where)
        if table:
            lines += ["", f"[{where}]"] + [f"{k} = {_toml_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"
