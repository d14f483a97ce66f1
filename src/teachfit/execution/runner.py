"""Run a set-point trajectory on a robot for a task and report what happened.

The runner only talks to the :class:`~teachfit.robot.interface.Robot` protocol and to the
task's geometric success test, so the same code drives the simulated tool, a simulated arm or a
real driver. Each command tick (``command_rate``) it samples the trajectory, builds an
impedance command -- stiffness high along the motion and compliant across it (seed A), a
constant push into the surface added to the feed-forward -- and checks for insertion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from teachfit.control.impedance import aligned_stiffness
from teachfit.core.errors import ControlError, SimulationDiverged
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.robot.interface import Robot
from teachfit.tasks.base import Task


@dataclass(frozen=True)
class ExecutionConfig:
    """How a trajectory is executed (N/m, N·m/rad, N, s, Hz).

    ``stiffness_along`` / ``stiffness_across`` act in the x-y plane along / across the
    direction of the set-point's motion (``aligned=False``: ``stiffness_along`` everywhere);
    ``push_force`` presses the part onto the surface; ``settle_time`` is how long the runner
    waits after the trajectory ends before declaring failure.
    """

    command_rate: float = 100.0
    stiffness_along: float = 1500.0
    stiffness_across: float = 150.0
    stiffness_z: float = 100.0
    stiffness_rot: tuple[float, float, float] = (40.0, 40.0, 40.0)
    push_force: float = 6.0
    aligned: bool = True
    settle_time: float = 1.0
    log_rate: float = 100.0
    max_force: float = 80.0

    def __post_init__(self) -> None:
        if not 1.0 <= self.command_rate <= 1000.0:
            raise ControlError("command_rate must be within [1, 1000] Hz")
        if not 0 < self.log_rate <= 1000.0:
            raise ControlError("log_rate must be within (0, 1000] Hz")
        for name in (
            "stiffness_along",
            "stiffness_across",
            "stiffness_z",
            "push_force",
            "settle_time",
            "max_force",
        ):
            if getattr(self, name) < 0:
                raise ControlError(f"{name} must be >= 0")


@dataclass(frozen=True)
class Outcome:
    """Result of one execution.

    ``time_to_insertion`` (s) is NaN on failure; ``reason`` is ``"inserted"``, ``"timeout"``,
    ``"force-limit"`` or ``"diverged: ..."``.
    """

    success: bool
    reason: str
    time_to_insertion: float
    duration: float
    path_length: float
    peak_force: float


@dataclass(frozen=True)
class ExecutionLog:
    """Measured and commanded signals at ``log_rate`` (world frame, TCP)."""

    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    wrench: np.ndarray
    cmd_pos: np.ndarray
    cmd_wrench_ff: np.ndarray


class _Recorder:
    def __init__(self) -> None:
        self.rows: list[tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]
        self.rows = []

    def add(self, s: RobotState, cmd_pos: np.ndarray, ff: np.ndarray) -> None:
        self.rows.append((s.t, s.pos, s.quat, s.wrench, cmd_pos, ff))

    def log(self) -> ExecutionLog:
        cols = list(zip(*self.rows, strict=True)) if self.rows else [[]] * 6
        arrs = [np.asarray(c, dtype=float) for c in cols]
        return ExecutionLog(*arrs)


def run_trajectory(
    robot: Robot,
    task: Task,
    trajectory: SetpointTrajectory,
    start: Pose,
    config: ExecutionConfig | None = None,
) -> tuple[Outcome, ExecutionLog]:
    """Reset ``robot`` at ``start`` and execute ``trajectory`` (world frame) until insertion.

    Returns the :class:`Outcome` and an :class:`ExecutionLog`. A diverging simulation ends
    the run as a failure with that reason; it never raises.
    """
    cfg = config or ExecutionConfig()
    period = robot.control_period
    ticks_per_cmd = max(1, round(1.0 / (cfg.command_rate * period)))
    cmd_dt = ticks_per_cmd * period
    log_every = max(1, round(1.0 / (cfg.log_rate * cmd_dt)))
    horizon = trajectory.duration + cfg.settle_time
    push = np.array([0.0, 0.0, -cfg.push_force, 0.0, 0.0, 0.0])
    rot_k = np.asarray(cfg.stiffness_rot, dtype=float)
    direction = np.array([1.0, 0.0])
    rec = _Recorder()
    state = robot.reset(start)
    t0 = state.t
    prev = state.pos.copy()
    path = 0.0
    peak = 0.0
    reason = "timeout"
    t_ins = float("nan")
    k = 0
    while True:
        t = state.t - t0
        pos, quat, vel, ff = trajectory.sample(t)
        if np.hypot(vel[0], vel[1]) > 1e-6:
            direction = vel[:2]
        if cfg.aligned:
            stiff = aligned_stiffness(
                direction, cfg.stiffness_along, cfg.stiffness_across, cfg.stiffness_z, rot_k
            )
        else:
            stiff = np.diag([cfg.stiffness_along] * 2 + [cfg.stiffness_z] + list(rot_k))
        cmd_ff = ff + push
        robot.command(
            ImpedanceCommand(pos=pos, quat=quat, lin_vel=vel, wrench_ff=cmd_ff, stiffness=stiff)
        )
        if k % log_every == 0:
            rec.add(state, pos, cmd_ff)
        k += 1
        try:
            state = robot.step(ticks_per_cmd)
        except SimulationDiverged as exc:
            reason = f"diverged: {exc}"
            break
        path += float(np.linalg.norm(state.pos - prev))
        prev = state.pos
        peak = max(peak, float(np.linalg.norm(state.wrench[:3])))
        if task.detect_success(state.pose):
            reason = "inserted"
            t_ins = state.t - t0
            rec.add(state, pos, cmd_ff)
            break
        if peak > cfg.max_force:
            reason = "force-limit"
            break
        if state.t - t0 >= horizon:
            break
    outcome = Outcome(
        success=reason == "inserted",
        reason=reason,
        time_to_insertion=t_ins,
        duration=state.t - t0,
        path_length=path,
        peak_force=peak,
    )
    return outcome, rec.log()
