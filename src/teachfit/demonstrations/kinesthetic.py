"""A kinesthetic demonstration on a real robot: a person guides the compliant arm.

On the Franka twin a scripted hand (a guide, :mod:`teachfit.robot.franka.hand`) can stand in for
the person: it is handed to the twin once the recording's reset holds the arm, the twin pushes
the arm with it inside its physics, and the guide's lead-in (``t < 0``) is cut from the
recording, which then runs to the guide's end.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

from teachfit.core.control import ControllerSpec
from teachfit.core.errors import RobotFault
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.demonstrations.dataset import Demonstration
from teachfit.robot.franka.hand import Guide
from teachfit.robot.franka.record import KinestheticRecording, record_kinesthetic
from teachfit.robot.interface import Robot, TeacherHints
from teachfit.tasks.base import Task


def _demo(rec: KinestheticRecording, task: str, robot: Robot, hand: str) -> Demonstration:
    meta: dict[str, Any] = {"robot": robot.name, "interrupted": bool(rec.interrupted)}
    meta["fault"] = rec.fault
    if hand:
        meta["hand"] = hand
    return Demonstration(
        t=rec.t,
        pos=rec.pos,
        quat=rec.quat,
        wrench=rec.wrench,
        task=task,
        source="kinesthetic",
        name=f"{task}-kinesthetic",
        frame="world",
        child_frame="tcp",
        meta=meta,
    )


class _AfterReset:
    """``robot`` that calls ``begin()`` once its first reset returns (the recording's own:
    the arm held where it is, the wrench tared), so a scripted hand starts with the recording.
    """

    def __init__(self, robot: Robot, begin: Callable[[], None]) -> None:
        self.robot, self.begin = robot, begin
        self.name, self.wrench_source = robot.name, robot.wrench_source
        if hasattr(robot, "tap"):  # the Franka driver samples in its control thread
            self.tap, self.untap = getattr(robot, "tap"), getattr(robot, "untap")  # noqa: B009

    @property
    def control_period(self) -> float:
        return self.robot.control_period

    @property
    def time(self) -> float:
        return self.robot.time

    def reset(self, pose: Pose, controller: ControllerSpec | None = None) -> RobotState:
        state = self.robot.reset(pose, controller)
        self.begin()
        return state

    def state(self) -> RobotState:
        return self.robot.state()

    def command(self, cmd: ImpedanceCommand) -> None:
        self.robot.command(cmd)

    def step(self, n: int = 1) -> RobotState:
        return self.robot.step(n)

    def finish_execution(self) -> None:
        self.robot.finish_execution()

    def close(self) -> None:
        self.robot.close()

    def teacher_hints(self, task: Task) -> TeacherHints:
        return self.robot.teacher_hints(task)


def _after_lead_in(rec: KinestheticRecording, lead_in: float) -> KinestheticRecording:
    """``rec`` from ``lead_in`` s on, its time from 0 again."""
    keep = rec.t >= lead_in - 1e-9
    if not keep.any():
        return rec
    return replace(
        rec,
        t=rec.t[keep] - rec.t[keep][0],
        pos=rec.pos[keep],
        quat=rec.quat[keep],
        wrench=rec.wrench[keep],
    )


def record_demonstration(
    robot: Robot,
    task: str,
    duration: float | None = None,
    rate_hz: float = 100.0,
    hand: tuple[Guide, Callable[[Guide], None], str] | None = None,
) -> Demonstration:
    """Record one demonstration while a person guides ``robot`` (zero stiffness, light
    damping) for ``duration`` s or until Ctrl-C; every sample is kept. A robot fault keeps the
    samples too: they are returned, with the fault's message in ``meta["fault"]``.

    ``hand``: ``(guide, send, name)`` a scripted hand instead of a person: ``send(guide)``
    hands it to the twin once the recording's reset holds the arm; the recording lasts the
    guide (``duration`` is ignored) and starts at its ``t = 0`` (``meta["hand"] = name``)."""
    lead_in, name = 0.0, ""
    if hand is not None:
        guide, send, name = hand
        robot = _AfterReset(robot, lambda: send(guide))
        lead_in, duration = guide.lead_in, guide.lead_in + guide.end
    try:
        rec = record_kinesthetic(robot, duration=duration, rate_hz=rate_hz)
    except RobotFault as exc:
        partial: KinestheticRecording | None = getattr(exc, "recording", None)
        if partial is None or len(partial.t) < 2:
            raise
        rec = partial
    return _demo(_after_lead_in(rec, lead_in), task, robot, name)
