"""Task parameters: a frozen dataclass per task with documented fields and one-line checks.

Every task's parameters derive from :class:`TaskParams`: lengths in metres, angles in radians.
The sign checks of the fields named in ``positive`` / ``nonnegative`` run first, then the
relations between fields (:meth:`TaskParams.check`); every failure is a :class:`TaskError`
whose message starts with the task's name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

from teachfit.core.errors import TaskError


def doc_field(text: str, default: float | int) -> Any:
    """A dataclass field with a default and a description for ``teachfit tasks``."""
    return field(default=default, metadata={"doc": text})


@dataclass(frozen=True)
class TaskParams:
    """Base of every task's parameters (no fields of its own)."""

    #: task name prefixed to every validation message
    task_name: ClassVar[str] = "task"
    #: fields that must be > 0
    positive: ClassVar[tuple[str, ...]] = ()
    #: fields that must be >= 0
    nonnegative: ClassVar[tuple[str, ...]] = ()

    def __post_init__(self) -> None:
        for key in self.positive:
            value = getattr(self, key)
            self.require(value > 0, f"{key} must be > 0, got {value}")
        for key in self.nonnegative:
            value = getattr(self, key)
            self.require(value >= 0, f"{key} must be >= 0, got {value}")
        self.check()

    def check(self) -> None:
        """Check relations between fields; subclasses extend it (calling ``super().check()``)."""

    def require(self, condition: bool, message: str) -> None:
        """Raise :class:`TaskError` with ``message`` (prefixed by the task name) unless true."""
        if not condition:
            raise TaskError(f"{self.task_name}: {message}")

    def require_reachable(self, success_depth: float, depth: float, hole: str) -> None:
        """The success depth (m) must not lie deeper than the ``hole``'s depth (m)."""
        self.require(
            success_depth <= depth,
            f"success_depth {success_depth} is deeper than the {hole} ({depth}): "
            "impossible to succeed",
        )
