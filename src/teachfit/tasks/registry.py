"""Built-in tasks by name, their search dimensions, and loading a task from a name or a file."""

from __future__ import annotations

from pathlib import Path

from teachfit.core.errors import TaskError
from teachfit.tasks.base import Task, read_task_toml
from teachfit.tasks.geometry.key import Key
from teachfit.tasks.geometry.peg import AluminiumPeg
from teachfit.tasks.geometry.peg2d import Peg2D
from teachfit.tasks.geometry.puzzle import Puzzle
from teachfit.tasks.geometry.socket3d import Socket3D

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
