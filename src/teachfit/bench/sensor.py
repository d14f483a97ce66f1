"""How much the measured contact force looks like a real sensor's: f_z smoothness at 100 Hz.

Issue 11's goal for steady sliding: the standard deviation of f_z at most 0.5 N and its lag-1
autocorrelation at least 0.9 at 100 Hz. Two recordings, on any robot of the registry:

- :func:`teacher_smoothness`: one seeded blind-teacher demonstration (the recording every
  search model learns from), samples from 1 s after its start to 1 s before it ends, whole and
  per straight pass of the sweep (a pass: the heading steady within 20° for 0.5 s either
  side; its mean differs from pass to pass on the arm, where joint friction loads the press);
- :func:`slide_smoothness`: a short straight slide on the block top with the teacher's
  stiffness and press (its slow wander included), the quick check the tests run.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.follow import run_trajectory
from teachfit.execution.teacher import (
    BlindTeacher,
    TeacherStyle,
    follow_config,
    press_wander,
    with_hints,
)
from teachfit.robot.registry import make_robot
from teachfit.tasks.registry import get_task

GOAL_STD, GOAL_LAG1 = 0.5, 0.9  # N, at 100 Hz


@dataclass(frozen=True)
class Smoothness:
    """f_z figures of one recording at 100 Hz: ``mean`` and ``std`` (N), ``lag1`` (the lag-1
    autocorrelation), ``n`` samples."""

    mean: float
    std: float
    lag1: float
    n: int

    @classmethod
    def of(cls, fz: np.ndarray) -> Smoothness:
        """The figures of the samples ``fz`` (N), consecutive at 100 Hz."""
        x = np.asarray(fz, dtype=float)
        if x.size < 3:
            raise ValueError("smoothness needs at least 3 samples")
        lag1 = float(np.corrcoef(x[:-1], x[1:])[0, 1]) if x.std() > 0 else 1.0
        return cls(float(x.mean()), float(x.std()), lag1, int(x.size))

    @property
    def meets_goal(self) -> bool:
        return self.std <= GOAL_STD and self.lag1 >= GOAL_LAG1


@dataclass(frozen=True)
class TeacherSmoothness:
    """:func:`teacher_smoothness`'s result: ``whole`` window, the ``passes`` (straight passes,
    each of at least 1 s), the demonstration's ``duration`` (s)."""

    whole: Smoothness
    passes: tuple[Smoothness, ...]
    duration: float

    @property
    def pass_std(self) -> float:
        """Median per-pass standard deviation (N)."""
        return float(np.median([p.std for p in self.passes])) if self.passes else float("nan")

    @property
    def pass_lag1(self) -> float:
        """Median per-pass lag-1 autocorrelation."""
        return float(np.median([p.lag1 for p in self.passes])) if self.passes else float("nan")


def _straight(pos: np.ndarray, rate: float, half: float = 0.5, tol_deg: float = 20.0):
    """(T,) bool: the planar heading 0.5 s before and after is within ``tol_deg`` of now's."""
    k = max(1, int(round(0.1 * rate)))
    vel = np.zeros((len(pos), 2))
    vel[k:-k] = pos[2 * k :, :2] - pos[: -2 * k, :2]
    heading = np.arctan2(vel[:, 1], vel[:, 0])
    h = int(round(half * rate))
    ok = np.zeros(len(pos), dtype=bool)
    for i in range(h + k, len(pos) - h - k):
        d = np.angle(np.exp(1j * (heading[i - h : i + h + 1] - heading[i])))
        ok[i] = bool(np.all(np.abs(d) < np.radians(tol_deg)))
    return ok


def teacher_smoothness(
    robot: str = "floating", task: str = "peg2d", seed: int = 0, margin: float = 1.0
) -> TeacherSmoothness:
    """f_z figures of the seeded teacher's first demonstration of ``task`` on ``robot``."""
    demo = BlindTeacher(get_task(task), seed=seed, robot=robot).record(1)[0][0]
    t, fz = np.asarray(demo.t), np.asarray(demo.wrench)[:, 2]
    rate = 1.0 / float(np.median(np.diff(t)))
    window = (t > margin) & (t < t[-1] - margin)
    straight = _straight(np.asarray(demo.pos), rate) & window
    edges = np.flatnonzero(np.diff(np.concatenate([[0], straight.astype(int), [0]])))
    runs = zip(edges[::2], edges[1::2], strict=True)
    passes = tuple(Smoothness.of(fz[a:b]) for a, b in runs if b - a >= rate)
    return TeacherSmoothness(Smoothness.of(fz[window]), passes, float(t[-1]))


def slide_smoothness(
    robot: str = "floating",
    task: str = "peg2d",
    seed: int = 0,
    duration: float = 4.0,
    start_xy: tuple[float, float] = (0.035, -0.024),
    style: TeacherStyle | None = None,
    **options: Any,
) -> Smoothness:
    """f_z figures of a ``duration`` s straight slide along +y at the teacher's speed from
    ``start_xy`` (m, task frame) on the block top, driven as the teacher drives the robot
    (:func:`~teachfit.execution.teacher.follow_config`: its stiffness and press, the press's
    slow wander seeded by ``seed``), through the execution engine; samples after the first
    0.5 s (``options`` go to the robot, e.g. ``sensor="wrist-ft"`` on the FR3)."""
    the_task = get_task(task)
    bot = make_robot(robot, the_task, seed=seed, **options)
    # the robot's teacher hints (e.g. its press by feel), not the task's search pattern
    st = with_hints(style or TeacherStyle(), bot.teacher_hints(the_task))
    dt = 0.01
    n = int(round((duration + 0.5) / dt)) + 1
    start = the_task.contact_pose(np.asarray(start_xy, dtype=float))
    t = dt * np.arange(n)
    pos = start.pos + np.outer(t, [0.0, st.speed, 0.0])
    ff = np.zeros((n, 6))
    ff[:, 2] = -press_wander(st, n, dt, np.random.default_rng(seed))
    plan = SetpointTrajectory.from_path(
        t, pos, np.tile(start.quat, (n, 1)), wrench_ff=ff, name="slide"
    )
    try:
        log = run_trajectory(bot, the_task, plan, start, follow_config(st)).log
    finally:
        bot.close()
    fz = np.asarray(log.wrench)[:, 2]
    return Smoothness.of(fz[(log.t > 0.5) & (log.t <= t[-1])])
