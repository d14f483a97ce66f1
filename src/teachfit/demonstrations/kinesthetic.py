"""A kinesthetic demonstration on a real robot: a person guides the compliant arm."""

from __future__ import annotations

from teachfit.core.errors import RobotFault
from teachfit.demonstrations.dataset import Demonstration
from teachfit.robot.franka.record import KinestheticRecording, record_kinesthetic
from teachfit.robot.interface import Robot


def _demo(rec: KinestheticRecording, task: str, robot: Robot) -> Demonstration:
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
        meta={"robot": robot.name, "interrupted": bool(rec.interrupted), "fault": rec.fault},
    )


def record_demonstration(
    robot: Robot, task: str, duration: float | None = None, rate_hz: float = 100.0
) -> Demonstration:
    """Record one demonstration while a person guides ``robot`` (zero stiffness, light
    damping) for ``duration`` s or until Ctrl-C; every sample is kept. A robot fault keeps the
    samples too: they are returned, with the fault's message in ``meta["fault"]``."""
    try:
        rec = record_kinesthetic(robot, duration=duration, rate_hz=rate_hz)
    except RobotFault as exc:
        partial: KinestheticRecording | None = getattr(exc, "recording", None)
        if partial is None or len(partial.t) < 2:
            raise
        rec = partial
    return _demo(rec, task, robot)
