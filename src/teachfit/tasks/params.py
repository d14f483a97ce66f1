"""Task parameters: a frozen dataclass per task with documented fields and one-line checks.

Every task's parameters derive from :class:`TaskParams`: lengths in metres, angles in radians.
Each field states its description and its bound (:func:`doc_field`); the bounds are checked
first, in field order, then the relations between fields (:meth:`TaskParams.check`). Every
failure is a :class:`TaskError` whose message starts with the task's name.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from teachfit.core.errors import TaskError


def doc_field(
    text: str,
    default: float | int,
    above: float | None = None,
    at_least: float | None = None,
) -> Any:
    """A dataclass field with a default, a description for ``teachfit tasks`` and optionally
    a bound: the value must be ``> above`` or ``>= at_least``."""
    return field(default=default, metadata={"doc": text, "above": above, "at_least": at_least})


@dataclass(frozen=True)
class TaskParams:
    """Base of every task's parameters (no fields of its own)."""

    #: task name prefixed to every validation message
    task_name: ClassVar[str] = "task"

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            above, at_least = f.metadata.get("above"), f.metadata.get("at_least")
            if above is not None:
                self.require(value > above, f"{f.name} must be > {above}, got {value}")
            if at_least is not None:
                self.require(value >= at_least, f"{f.name} must be >= {at_least}, got {value}")
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
