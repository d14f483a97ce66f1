"""Simulation speed: raw ``mj_step`` vs. the controller in the loop, in contact on a task.

Both loops start from the same state: the tool pressed onto the surface at the teacher's start.
The raw loop keeps the last controller wrench applied (``qfrc_applied`` persists), so it stays
in the same contact; the controlled loop recomputes the impedance law every 1 ms tick.

For the FR3 (``robot="fr3"``) the controlled loop runs the whole 1 ms tick (torque law, limits,
wrench sensing) and the raw loop replays its torques through the bare physics step; the torque
law's compute time per tick is also timed (median and 99th percentile).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Protocol, cast

import mujoco
import numpy as np

from teachfit.core.errors import TeachfitError
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.interface import Robot
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


class _MujocoRobot(Robot, Protocol):
    """A robot simulated in MuJoCo: its model and data are open to the measurement."""

    model: mujoco.MjModel
    data: mujoco.MjData


class _TimedRobot(_MujocoRobot, Protocol):
    """The FR3, whose compiled tick also times the torque law."""

    def step_timed(self, n: int) -> tuple[np.ndarray, np.ndarray]: ...

    def replay(self, log: np.ndarray) -> None: ...


def _pressed_robot(task: Task, name: str) -> tuple[_MujocoRobot, ImpedanceCommand]:
    robot = make_robot(name, task)
    if not (hasattr(robot, "model") and hasattr(robot, "data")):
        raise TeachfitError(f"robot {name!r} is not simulated in MuJoCo: no simulation speed")
    robot = cast(_MujocoRobot, robot)  # checked just above
    start = task.protocol.teacher_start(np.random.default_rng(0))
    robot.reset(start)
    cmd = ImpedanceCommand(
        pos=start.pos,
        quat=start.quat,
        lin_vel=np.array([0.01, 0.0, 0.0]),
        wrench_ff=np.array([0, 0, -6.0, 0, 0, 0]),
        stiffness=np.array([1500, 150, 100, 40, 40, 40]),
        expires_after=60.0,  # one command slides the tool for the whole measurement
    )
    robot.command(cmd)
    robot.step(300)  # settle into contact; the raw loop keeps the last applied wrench
    return robot, cmd


def _contacts_while(sim: _MujocoRobot, steps: int) -> int:
    """The most contacts seen over ``steps`` controlled ticks (a sliding part can hop)."""
    most = 0
    for _ in range(steps):
        sim.step(1)
        most = max(most, int(sim.data.ncon))
    return most


@dataclass(frozen=True)
class ArmSimSpeed(SimSpeed):
    """:class:`SimSpeed` plus the torque law's compute time per tick (µs)."""

    compute_p50_us: float = 0.0
    compute_p99_us: float = 0.0


def measure_sim_speed(
    task: Task, steps: int = 5000, repeats: int = 3, robot: str = "floating"
) -> SimSpeed:
    """Best-of-``repeats`` throughput of both loops on the simulated ``robot``, interleaved so
    that load noise hits both."""
    if steps < 1 or repeats < 1:
        raise TeachfitError(f"steps and repeats must be >= 1, got {steps}, {repeats}")
    if robot == "fr3":
        return measure_fr3_speed(task, steps, repeats)
    raw_best = ctl_best = 0.0
    contacts = 0
    for _ in range(repeats):
        sim, cmd = _pressed_robot(task, robot)
        m, d = sim.model, sim.data
        snapshot = (d.qpos.copy(), d.qvel.copy(), d.time)
        t0 = time.perf_counter()
        for _ in range(steps):
            mujoco.mj_step(m, d)
        raw_best = max(raw_best, steps / (time.perf_counter() - t0))
        d.qpos[:], d.qvel[:], d.time = snapshot
        mujoco.mj_forward(m, d)
        sim.command(cmd)
        t0 = time.perf_counter()
        sim.step(steps)
        ctl_best = max(ctl_best, steps / (time.perf_counter() - t0))
        contacts = max(contacts, _contacts_while(sim, 50))
    rtf = ctl_best * sim.control_period
    return SimSpeed(raw_best, ctl_best, ctl_best / raw_best, rtf, contacts)


def measure_fr3_speed(task: Task, steps: int = 5000, repeats: int = 3) -> ArmSimSpeed:
    """The FR3's figures: the raw physics step vs. the full controlled tick (best of ``repeats``,
    interleaved), and the torque law's compute time per tick (p50, p99 over all ticks).

    The controlled tick runs as one compiled loop (:mod:`teachfit.robot.fr3.kernel`), so the
    raw loop is compiled too: from the same pressed state it replays the controlled run's
    torques through the bare physics step (:meth:`FR3Robot.replay`: ``mj_step1``, the joints'
    Stribeck term, ``mj_step2``; the same states, contacts and solver work, no Python per
    step), so the ratio is what the controller adds to the physics. Speeds are in CPU
    seconds of this thread (``time.thread_time``): on a shared machine other jobs' time does
    not count, and on an idle one it equals the wall clock. The compute time is measured
    inside the loop around the law and the torque map of each tick (wall clock, ns).
    """
    raw_best = ctl_best = 0.0
    contacts = 0
    samples: list[np.ndarray] = []
    robot = None
    for _ in range(repeats):
        pressed, _cmd = _pressed_robot(task, "fr3")
        robot = cast(_TimedRobot, pressed)  # the FR3
        m, d = robot.model, robot.data
        snapshot = (d.qpos.copy(), d.qvel.copy(), d.ctrl.copy(), d.qacc_warmstart.copy(), d.time)
        contacts = max(contacts, int(d.ncon))
        t0 = time.thread_time()
        ticks, log = robot.step_timed(steps)
        ctl_best = max(ctl_best, steps / (time.thread_time() - t0))
        samples.append(ticks)
        d.qpos[:], d.qvel[:], d.ctrl[:], d.qacc_warmstart[:], d.time = snapshot
        mujoco.mj_forward(m, d)
        t0 = time.thread_time()
        robot.replay(log)
        raw_best = max(raw_best, steps / (time.thread_time() - t0))
    assert robot is not None
    rtf = ctl_best * robot.control_period
    per_tick = np.concatenate(samples)
    return ArmSimSpeed(
        raw_best,
        ctl_best,
        ctl_best / raw_best,
        rtf,
        contacts,
        float(np.percentile(per_tick, 50)),
        float(np.percentile(per_tick, 99)),
    )
