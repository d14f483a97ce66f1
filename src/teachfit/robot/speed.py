"""Simulation speed: raw ``mj_step`` vs. the controller in the loop, in contact on a task.

Both loops start from the same state: the tool pressed onto the surface at the teacher's start.
The raw loop keeps the last controller wrench applied (``qfrc_applied`` persists), so it stays
in the same contact; the controlled loop recomputes the impedance law every 1 ms tick.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import mujoco
import numpy as np

from teachfit.core.errors import TeachfitError
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.registry import make_robot
from teachfit.tasks.base import Task


@dataclass(frozen=True)
class SimSpeed:
    """Steps per second (wall clock), their ratio, and the real-time factor with control."""

    raw_steps_per_s: float
    controlled_steps_per_s: float
    ratio: float
    real_time_factor: float
    contacts: int


def _pressed_robot(task: Task, name: str) -> tuple[object, ImpedanceCommand]:
    robot = make_robot(name, task)
    if not (hasattr(robot, "model") and hasattr(robot, "data")):
        raise TeachfitError(f"robot {name!r} is not simulated in MuJoCo: no simulation speed")
    start = task.protocol.teacher_start(np.random.default_rng(0))
    robot.reset(start)
    cmd = ImpedanceCommand(
        pos=start.pos,
        quat=start.quat,
        lin_vel=[0.01, 0.0, 0.0],
        wrench_ff=[0, 0, -6.0, 0, 0, 0],
        stiffness=[1500, 150, 100, 40, 40, 40],
    )
    robot.command(cmd)
    robot.step(300)  # settle into contact; the raw loop keeps the last applied wrench
    return robot, cmd


def measure_sim_speed(
    task: Task, steps: int = 5000, repeats: int = 3, robot: str = "floating"
) -> SimSpeed:
    """Best-of-``repeats`` throughput of both loops on the simulated ``robot``, interleaved so
    that load noise hits both."""
    if steps < 1 or repeats < 1:
        raise TeachfitError(f"steps and repeats must be >= 1, got {steps}, {repeats}")
    raw_best = ctl_best = 0.0
    contacts = 0
    for _ in range(repeats):
        sim, cmd = _pressed_robot(task, robot)
        m, d = sim.model, sim.data  # type: ignore[attr-defined]
        snapshot = (d.qpos.copy(), d.qvel.copy(), d.time)
        t0 = time.perf_counter()
        for _ in range(steps):
            mujoco.mj_step(m, d)
        raw_best = max(raw_best, steps / (time.perf_counter() - t0))
        d.qpos[:], d.qvel[:], d.time = snapshot
        mujoco.mj_forward(m, d)
        sim.command(cmd)  # type: ignore[attr-defined]
        contacts = int(d.ncon)
        t0 = time.perf_counter()
        sim.step(steps)  # type: ignore[attr-defined]
        ctl_best = max(ctl_best, steps / (time.perf_counter() - t0))
    rtf = ctl_best * sim.control_period  # type: ignore[attr-defined]
    return SimSpeed(raw_best, ctl_best, ctl_best / raw_best, rtf, contacts)
