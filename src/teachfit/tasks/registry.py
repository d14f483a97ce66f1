"""The one task registry: every task by name, their search dimensions, and loading a task from
a name or a file.

- :data:`TASKS`: the simulated cells of the search and skill papers (``peg2d``, ``socket3d``,
  ``puzzle``, ``key``, ``peg``);
- :data:`~teachfit.tasks.parts.PARTS`: the planning paper's parts (``l-groove``, ``tenon``),
  whose cells are :class:`~teachfit.tasks.geometry.parts_cell.PartsCell` and whose assemblies
  :func:`build_assembly` gives;
- task files (``.toml``): a built-in kind with other parameters, or a user's meshes
  (``task = "mesh"``), which have an assembly too.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from teachfit.core.errors import TaskError
from teachfit.tasks.base import Task, read_task_toml
from teachfit.tasks.geometry.key import Key
from teachfit.tasks.geometry.peg import AluminiumPeg
from teachfit.tasks.geometry.peg2d import Peg2D
from teachfit.tasks.geometry.puzzle import Puzzle
from teachfit.tasks.geometry.socket3d import Socket3D
from teachfit.tasks.parts import PARTS, Assembly, part_assembly

TASKS: dict[str, type[Task]] = {
    cls.name: cls for cls in (Peg2D, Socket3D, Puzzle, Key, AluminiumPeg)
}


def _is_file(name: str) -> bool:
    return name.endswith(".toml") and name not in TASKS


def _kind(path: Path) -> str:
    data = read_task_toml(path)
    kind = data.get("task")
    if kind != "mesh" and kind not in TASKS:
        raise TaskError(
            f"{path}: 'task' must name one of {sorted(TASKS)} or \"mesh\", got {kind!r}"
        )
    return str(kind)


def search_dims_of(name: str) -> tuple[str, ...]:
    """Searched degrees of freedom of the task ``name`` (built-in, or a task file), e.g.
    ``("x", "y", "rz")``."""
    if _is_file(name):
        path = Path(name)
        if _kind(path) == "mesh":
            from teachfit.tasks.mesh.spec import read_spec

            return read_spec(path).search_dims
        return load_task(name).search_dims
    try:
        return TASKS[name].search_dims
    except KeyError:
        raise TaskError(f"unknown task {name!r}; built-in tasks: {sorted(TASKS)}") from None


def get_task(name: str, **overrides: object) -> Task:
    """A built-in task by name, or a task file (``.toml``), with optional parameter overrides."""
    if _is_file(name):
        return load_task(name, **overrides)
    try:
        cls = TASKS[name]
    except KeyError:
        raise TaskError(f"unknown task {name!r}; built-in tasks: {sorted(TASKS)}") from None
    return cls.from_mapping(overrides) if overrides else cls()


def load_task(spec: str, **overrides: object) -> Task:
    """A task from a built-in name or a TOML file whose ``task`` key names the kind: a
    built-in kind (its parameters) or ``"mesh"`` (a user's meshes,
    :mod:`teachfit.tasks.mesh`); ``overrides`` replace parameters."""
    if spec in TASKS:
        return get_task(spec, **overrides)
    path = Path(spec)
    if path.suffix == ".toml":
        kind = _kind(path)
        if kind == "mesh":
            from teachfit.tasks.mesh.task import load_mesh_task

            return load_mesh_task(path, **overrides)  # type: ignore[arg-type]
        task = TASKS[kind].from_toml(path)
        if overrides:
            values = {f[0]: f[1] for f in task.param_table()} | dict(overrides)
            return TASKS[kind].from_mapping(values)
        return task
    raise TaskError(f"unknown task {spec!r}; built-in tasks: {sorted(TASKS)} (or a .toml file)")


def task_names() -> dict[str, str]:
    """Every built-in task name -> what it is for (``teachfit tasks`` lists them)."""
    sims = {name: "simulated cell (search, skill, assemble)" for name in TASKS}
    return sims | {name: "parts planned for (plan, capture, assemble)" for name in PARTS}


def part_tables() -> dict[str, list[tuple[str, float]]]:
    """Each planning part's dimensions (m) and their defaults."""
    return {
        name: [(f.name, float(getattr(cls(), f.name))) for f in dataclasses.fields(cls)]
        for name, cls in PARTS.items()
    }


def build_assembly(task: str, **overrides: float) -> Assembly:
    """The planning assembly of a built-in part (``l-groove``, ``tenon``; dimension overrides
    in m) or of a mesh task file (``.toml``: its exact meshes,
    :mod:`teachfit.tasks.mesh.assembly`).

    Raises
    ------
    TaskError
        Unknown task name, unknown or invalid dimension, overrides for a mesh task.
    """
    if _is_file(task) and task not in PARTS:
        if overrides:
            raise TaskError("a mesh task's dimensions are in its meshes: no overrides")
        from teachfit.tasks.mesh.assembly import mesh_assembly

        return mesh_assembly(task)
    return part_assembly(task, **overrides)
