"""Typed exceptions. Every error teachfit raises on purpose derives from :class:`TeachfitError`."""

from __future__ import annotations


class TeachfitError(Exception):
    """Base class of all errors raised by teachfit on purpose (bad input, impossible requests)."""


class TaskError(TeachfitError):
    """Impossible or inconsistent task parameters (e.g. a peg wider than its hole)."""


class DatasetError(TeachfitError):
    """A demonstration file or import that cannot be read or is invalid.

    Attributes name where the problem is, so that the message can point a user at it.
    """

    def __init__(
        self,
        message: str,
        *,
        path: str | None = None,
        row: int | None = None,
        column: str | None = None,
    ) -> None:
        self.path = path
        self.row = row
        self.column = column
        where = []
        if path is not None:
            where.append(f"file {path}")
        if row is not None:
            where.append(f"row {row}")
        if column is not None:
            where.append(f"column {column!r}")
        prefix = f"{', '.join(where)}: " if where else ""
        super().__init__(prefix + message)


class ControlError(TeachfitError):
    """Invalid controller gains, limits or commands."""


class RobotFault(TeachfitError):
    """The robot stopped executing: what a real arm reports as a fault, or a broken simulation.

    The execution engine ends the run with the matching :class:`~teachfit.core.outcome.Outcome`
    and keeps everything recorded so far; nothing more is commanded to a faulted robot.
    """


class ReflexFault(RobotFault):
    """A safety reflex stopped the arm (contact force/torque or joint torque over its threshold)."""


class LimitViolation(RobotFault):
    """A command or the measured motion broke a limit (joint, speed, wrench, workspace box)."""


class ConnectionLost(RobotFault):
    """The connection to the robot (or its control loop) was lost."""


class NeedsAPerson(RobotFault):
    """The cell cannot go on without a person: a part lost from the grasp or caught in the
    hole, a reset declined. A learning run stops at once (its finished trials kept) instead of
    charging the trial, and the person continues it with ``--resume``."""


class SimulationDiverged(RobotFault):
    """The physics simulation produced NaN/inf or MuJoCo raised a warning that invalidates it."""


class ModelError(TeachfitError):
    """A learned model cannot be fitted or loaded (too few samples, wrong task or dimension)."""


class PlanningError(TeachfitError):
    """An invalid planning request (start in collision, wrong parts, empty demonstration)."""


class RenderError(TeachfitError):
    """Offscreen rendering is unavailable (no OpenGL / EGL / OSMesa)."""


class CaptureError(TeachfitError):
    """Video capture of a demonstration failed: bad rig/marker file, unreadable or mismatched
    videos, markers never seen."""


class SkillError(TeachfitError):
    """An invalid skill: graph, condition, primitive or parameter; names the node when one is
    at fault (``node`` attribute)."""

    def __init__(self, message: str, *, node: str | None = None) -> None:
        self.node = node
        super().__init__(f"node {node!r}: {message}" if node is not None else message)


class OutputError(TeachfitError, OSError):
    """An output file or folder cannot be written (folder cannot be created, disk full,
    read-only file system). Also an :class:`OSError`, so callers that catch write errors as
    ``OSError`` keep doing so."""
