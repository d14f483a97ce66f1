"""A simulated blind teacher: a "human with closed eyes" demonstrating a search.

The teacher starts from a worst-case offset, presses the part onto the surface and moves the
compliant robot kinesthetically in a deliberate search pattern until the part drops in. The
belief about where the hole is is off by ``belief_sigma``. Patterns:

- ``"sweep"`` (default, the worst-case demonstration Ehlers et al. 2019 asks for): a raster of
passes
  across the believed direction, ``2 sweep_halfwidth`` wide and ``spiral_pitch`` apart, that
  starts at the start pose and advances towards (and beyond) the belief. The demonstrated
  states then span the whole region between the start and the hole, so "one end of the
  exploration distribution is approximately at the starting position" (Ehlers et al. 2019, Sec.
  IV-B).
- ``"spiral"``: straight towards the belief, then an outward Archimedean spiral around it.
- ``"zigzag"``: straight towards the belief, then a zig-zag raster around it.

Human-like noise is a slow random wander (an Ornstein-Uhlenbeck process) plus a small
physiological tremor; for tasks with a rotational search DOF the teacher also wiggles the part
about z around its belief. The press is not constant either: it wanders slowly around
``push_force`` (another Ornstein-Uhlenbeck process, ``press_wander`` N over ``press_timescale``
s; see :meth:`BlindTeacher.press`). What is recorded is what a kinesthetic demonstration
records: TCP pose and wrist wrench at ``record_rate``. Demonstrations that end at once or never
are discarded, as in Ehlers et al. 2019.

The style and the hints of a task and a robot are in :mod:`.teacher_style`, the hand's path,
noise and press in :mod:`.teacher_motion`; this module records with them (a progress bar, and
the disk cache of :mod:`.teacher_cache`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from rich.progress import Progress

from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import Pose
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.demonstrations.dataset import Demonstration
from teachfit.execution.follow import run_trajectory
from teachfit.execution.teacher_cache import cache_key, cached
from teachfit.execution.teacher_motion import hand_plan, press_wander
from teachfit.execution.teacher_style import (
    PATTERNS,
    TeacherStyle,
    follow_config,
    style_for,
    unchamfered_hints,
    with_hints,
)
from teachfit.robot.registry import make_robot
from teachfit.tasks.base import Task

#: the teacher's style and hand, importable from here too
__all__ = [
    "PATTERNS",
    "BlindTeacher",
    "TeacherStyle",
    "follow_config",
    "press_wander",
    "style_for",
    "unchamfered_hints",
    "with_hints",
]


class BlindTeacher:
    """Records demonstrations of ``task`` with a simulated blind human (seeded)."""

    def __init__(
        self,
        task: Task,
        style: TeacherStyle | None = None,
        seed: int = 0,
        robot: str = "floating",
    ) -> None:
        self.task = task
        self.seed, self.robot_name = int(seed), robot
        self.rng = np.random.default_rng(seed)
        # the press's own stream: the plans' other draws stay what they were without it
        self._press_rng = np.random.default_rng([int(seed), 0x70726573])
        self.robot = make_robot(robot, task, seed=int(self.rng.integers(2**31)))
        self.style = style_for(task, style, self.robot)
        self._fresh = True  # nothing recorded yet: a recording depends on the seed alone
        self._replayed = False
        self.has_rz = "rz" in task.search_dims

    # ------------------------------------------------------------------------ planning
    def press(self, n: int, dt: float) -> np.ndarray:
        """(n,) the press's slow deviation from ``push_force`` (N): :func:`press_wander`."""
        return press_wander(self.style, n, dt, self._press_rng)

    def plan(self, start: Pose) -> SetpointTrajectory:
        """The path the teacher's hand intends, world frame, for ``max_duration``
        (:func:`~teachfit.execution.teacher_motion.hand_plan`)."""
        return hand_plan(self.task, self.style, self.rng, self._press_rng, start)

    # ----------------------------------------------------------------------- recording
    def demonstrate(self, start: Pose | None = None) -> tuple[Demonstration | None, str]:
        """One attempt. Returns ``(demo, "ok")`` or ``(None, why it was discarded)``."""
        st = self.style
        if self._replayed:
            raise TeachfitError(
                "this teacher's first recording came from the teacher cache "
                "(TEACHFIT_TEACHER_CACHE), so its random state is not where a recording left it: "
                "record more with a new BlindTeacher"
            )
        self._fresh = False
        start = start or self.task.protocol.teacher_start(self.rng)
        cfg = follow_config(st)
        plan = self.plan(start)
        rate = min(st.record_rate, 100.0)
        outcome = run_trajectory(self.robot, self.task, plan, start, cfg, log_rate=rate)
        log = outcome.log
        if not outcome.success:
            return None, f"never reached the hole ({outcome.outcome}: {outcome.reason})"
        if outcome.time_to_success < st.min_duration:
            return None, f"ended at once ({outcome.time_to_success:.2f} s)"
        demo = Demonstration(
            t=log.t - log.t[0],
            pos=log.pos,
            quat=log.quat,
            wrench=log.wrench,
            task=self.task.name,
            source="simulated-teacher",
            frame="world",
            child_frame="tcp",
            meta={
                "pattern": st.pattern,
                "time_to_insertion": outcome.time_to_success,
                "path_length": outcome.path_length,
                "start": [float(v) for v in (*start.pos, *start.quat)],
            },
        )
        return demo, "ok"

    def record(
        self,
        n: int,
        *,
        max_attempts: int | None = None,
        progress: bool = False,
    ) -> tuple[list[Demonstration], list[str]]:
        """Record ``n`` accepted demonstrations; returns them and the reasons for discards.

        A first recording of a teacher is read from the folder named by the environment
        variable ``TEACHFIT_TEACHER_CACHE`` when it holds the same one (see
        :mod:`teachfit.execution.teacher_cache`).
        """
        if n <= 0:
            raise TeachfitError(f"number of demonstrations must be positive, got {n}")
        limit = max_attempts or 5 * n
        if self._fresh:
            key = cache_key(
                task=self.task,
                style=self.style,
                seed=self.seed,
                robot=self.robot_name,
                n=n,
                limit=limit,
            )
            self._fresh, self._replayed = False, True
            return cached(key, lambda: self._record_fresh(n, limit, progress))
        return self._record(n, limit, progress)

    def _record_fresh(
        self, n: int, limit: int, progress: bool
    ) -> tuple[list[Demonstration], list[str]]:
        self._replayed = False  # recorded here, not replayed: the state is where it should be
        return self._record(n, limit, progress)

    def _record(self, n: int, limit: int, progress: bool) -> tuple[list[Demonstration], list[str]]:
        demos: list[Demonstration] = []
        discarded: list[str] = []
        with Progress(disable=not progress, transient=True) as bar:
            task_id = bar.add_task("recording demonstrations", total=n)
            while len(demos) < n and len(demos) + len(discarded) < limit:
                demo, why = self.demonstrate()
                if demo is None:
                    discarded.append(why)
                    continue
                name = f"{self.task.name}-teacher-{len(demos)}"
                demos.append(replace(demo, name=name, meta=dict(demo.meta)))
                bar.advance(task_id)
        if len(demos) < n:
            raise TeachfitError(
                f"only {len(demos)} of {n} demonstrations succeeded in {limit} attempts; "
                f"discarded: {discarded}"
            )
        return demos, discarded
