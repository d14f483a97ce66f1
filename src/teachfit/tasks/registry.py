"""Built-in tasks by name, and loading a task from a name or a TOML file."""

from __future__ import annotations

from pathlib import Path

from teachfit.core.errors import TaskError
from teachfit.tasks.base import Task
from teachfit.tasks.key import Key
from teachfit.tasks.peg import AluminiumPeg
from teachfit.tasks.peg2d import Peg2D
from teachfit.tasks.puzzle import Puzzle
from teachfit.tasks.socket3d import Socket3D

TASKS: dict[str, type[Task]] = {
    cls.name: cls for cls in (Peg2D, Socket3D, Puzzle, Key, AluminiumPeg)
}


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
        import tomllib

        try:
            data = tomllib.loads(path.read_text())
        except (OSError, tomllib.TOMLDecodeError) as exc:
            raise TaskError(f"cannot read task file {path}: {exc}") from exc
        kind = data.get("task")
        if kind not in TASKS:
            raise TaskError(f"{path}: 'task' must name one of {sorted(TASKS)}, got {kind!r}")
        return TASKS[kind].from_toml(path)
    raise TaskError(f"unknown task {spec!r}; built-in tasks: {sorted(TASKS)} (or a .toml file)")
