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


def search_dims_of(name: str) -> tuple[str, ...]:
    """Searched degrees of freedom of the built-in task ``name``, e.g. ``("x", "y", "rz")``."""
    try:
        return TASKS[name].search_dims
    except KeyError:
        raise TaskError(f"unknown task {name!r}; built-in tasks: {sorted(TASKS)}") from None


def get_task(name: str, **overrides: object) -> Task:
    """A built-in task by name, with optional parameter overrides."""
    try:
        cls = TASKS[name]
    except KeyError:
        raise TaskError(f"unknown task {name!r}; built-in tasks: {sorted(TASKS)}") from None
    return cls.from_mapping(overrides) if overrides else cls()


def load_task(spec: str) -> Task:
    """A task from a built-in name or a TOML file whose ``task`` key names the kind."""
    if spec in TASKS:
        return get_task(spec)
    path = Path(spec)
    if path.suffix == ".toml":
        data = read_task_toml(path)
        kind = data.get("task")
        if kind not in TASKS:
            raise TaskError(f"{path}: 'task' must name one of {sorted(TASKS)}, got {kind!r}")
        return TASKS[kind].from_toml(path)
    raise TaskError(f"unknown task {spec!r}; built-in tasks: {sorted(TASKS)} (or a .toml file)")
