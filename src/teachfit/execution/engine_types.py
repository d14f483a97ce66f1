"""The engine's settings (:class:`ExecConfig`) and what one execution returns
(:class:`ExecutionResult`, with the :class:`NodeVisit` s it made); the loop itself is
:func:`teachfit.execution.engine.execute`, which also exports these names."""

from __future__ import annotations

from dataclasses import dataclass

from teachfit.core.errors import SkillError
from teachfit.core.outcome import Outcome
from teachfit.execution.log import ExecutionLog


@dataclass(frozen=True)
class ExecConfig:
    """Engine settings: ``command_rate`` and ``log_rate`` (Hz); ``contact_force`` (N) marks
    first contact; ``max_time`` (s) is a hard cap besides the skill's own error condition;
    ``recovery_time`` (s) bounds the recovery node (0: skip recovery)."""

    command_rate: float = 100.0
    log_rate: float = 100.0
    contact_force: float = 2.0
    max_time: float = 30.0
    recovery_time: float = 0.5

    def __post_init__(self) -> None:
        if not 1.0 <= self.command_rate <= 1000.0:
            raise SkillError("command_rate must be within [1, 1000] Hz")
        if not 0 < self.log_rate <= self.command_rate:
            raise SkillError("log_rate must be within (0, command_rate]")
        if not (self.contact_force > 0 and self.max_time > 0 and self.recovery_time >= 0):
            raise SkillError("contact_force and max_time must be > 0, recovery_time >= 0")


@dataclass(frozen=True)
class NodeVisit:
    """One stay in a node: ``t_enter``, ``t_exit`` (s since the start), why it ended."""

    node: str
    t_enter: float
    t_exit: float
    reason: str


@dataclass(frozen=True)
class ExecutionResult:
    """What one execution did (times in s since the execution started).

    ``outcome`` says why it stopped and ``reason`` in words; ``time_to_success`` is NaN unless
    it succeeded; ``remaining`` (m) the TCP's distance to ``goal2world`` at the end (the last
    finite state if the simulation diverged); ``detected`` the task's success detector at the
    end (``None`` without a task); ``ground_truth_inserted`` the simulator's ground truth then
    (``None`` without a task or after a fault), for benchmarks only; ``reflex`` whether a
    safety reflex of the robot stopped it (a real arm's; the next reset recovers).
    """

    skill: str
    outcome: Outcome
    reason: str
    visits: tuple[NodeVisit, ...]
    t_first_contact: float
    t_end: float
    time_to_success: float
    path_length: float
    peak_force: float
    remaining: float
    detected: bool | None
    ground_truth_inserted: bool | None
    log: ExecutionLog
    node_names: tuple[str, ...]
    steps: int
    wall_s: float
    reflex: bool = False

    @property
    def success(self) -> bool:
        """The success condition fired (and, with a task, its detector agrees)."""
        return self.outcome is Outcome.SUCCESS and self.detected is not False

    @property
    def duration(self) -> float:
        return self.t_end
