"""How an execution ended: one :class:`Outcome` for searches, skills and assembly alike."""

from __future__ import annotations

from enum import Enum


class Outcome(Enum):
    """Why an execution stopped (the value is the word shown in tables and logs).

    ``SUCCESS``: the success condition (the task's detector, from what the robot measures)
    held. ``TIMEOUT``: time ran out (the trajectory and its settle time, or the skill's hard
    cap). ``ERROR_CONDITION``: a skill's error condition fired. ``PRECONDITION``: the skill could
    not start. ``FORCE_LIMIT``: the measured force exceeded the execution's limit.
    ``DIVERGED``: the simulation became invalid. ``CONTROL_ERROR``: the controller refused a
    command (e.g. a stiffness over its limit). ``FAULT``: the robot reported a fault (reflex,
    limit violation, lost connection).
    """

    SUCCESS = "success"
    TIMEOUT = "timeout"
    ERROR_CONDITION = "error-condition"
    PRECONDITION = "precondition"
    FORCE_LIMIT = "force-limit"
    DIVERGED = "diverged"
    CONTROL_ERROR = "control-error"
    FAULT = "robot-fault"

    @property
    def success(self) -> bool:
        return self is Outcome.SUCCESS

    def __str__(self) -> str:
        return self.value
