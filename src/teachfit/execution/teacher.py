"""A simulated blind teacher: a "human with closed eyes" demonstrating a search.

The teacher starts from a worst-case offset, presses the part onto the surface and moves the
compliant robot kinesthetically in a deliberate search pattern until the part drops in. The
belief about where the hole is is off by ``belief_sigma``. Patterns:

- ``"sweep"`` (default, the worst-case demonstration seed A asks for): a raster of passes
  across the believed direction, ``2 sweep_halfwidth`` wide and ``spiral_pitch`` apart, that
  starts at the start pose and advances towards (and beyond) the belief. The demonstrated
  states then span the whole region between the start and the hole, so "one end of the
  exploration distribution is approximately at the starting position" (seed A, Sec. IV-B).
- ``"spiral"``: straight towards the belief, then an outward Archimedean spiral around it.
- ``"zigzag"``: straight towards the belief, then a zig-zag raster around it.
 Human-like noise is a slow random
wander (an Ornstein-Uhlenbeck process) plus a small physiological tremor; for tasks with a
rotational search DOF the teacher also wiggles the part about z around its belief. The press
is not constant either: it wanders slowly around ``push_force`` (another Ornstein-Uhlenbeck
process, ``press_wander`` N over ``press_timescale`` s; see :meth:`BlindTeacher.press`). What is
recorded is what a kinesthetic demonstration records: TCP pose and wrist wrench at
``record_rate``. Demonstrations that end at once or never are discarded, as in seed A.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from rich.progress import Progress
from scipy.signal import lfilter

from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import Pose, quat_from_rz
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.demonstrations.dataset import Demonstration
from teachfit.execution.follow import run_trajectory
from teachfit.execution.teacher_cache import cache_key, cached
from teachfit.robot.interface import Robot
from teachfit.robot.registry import make_robot
from teachfit.skills.follow import FollowConfig
from teachfit.skills.tilt import TiltConfig
from teachfit.tasks.base import Task

PATTERNS = ("sweep", "spiral", "zigzag")


@dataclass(frozen=True)
class TeacherStyle:
    """How the simulated teacher searches (m, m/s, s, rad, N, N/m, Hz)."""

    pattern: str = "sweep"
    speed: float = 0.012
    belief_sigma: float = 0.005
    spiral_pitch: float = 0.0025
    sweep_halfwidth: float = 0.015
    wander_amplitude: float = 0.0005
    wander_timescale: float = 0.5
    #: time constant (s) of a first-order low-pass on the hand's wander and tremor, 0: none
    #: (the wander is then an Ornstein-Uhlenbeck path whose velocity is white at 100 Hz)
    hand_smoothing: float = 0.0
    tremor_amplitude: float = 0.00005
    tremor_frequency: float = 9.0
    rz_belief_sigma: float = 0.1
    rz_wiggle: float = 0.2
    rz_wiggle_frequency: float = 0.4
    push_force: float = 6.0
    press_wander: float = 0.3
    press_timescale: float = 1.0
    press_feel: float = 0.0
    arm_stiffness: float = 600.0
    max_duration: float = 60.0
    min_duration: float = 0.5
    record_rate: float = 100.0
    #: sinking (m) after which the hand stops moving the part sideways (None: never)
    hold_depth: float | None = None
    #: tilt of the held part (rad, 0: upright): leaning toward where it searches, the hand
    #: slides it to the hole's wall and turns it upright once it drops in (skills/tilt.py)
    tilt: float = 0.0
    #: how far (m) the tilted hand slides a dropped part at most (0: ``sweep_halfwidth``)
    tilt_reach: float = 0.0

    def __post_init__(self) -> None:
        if self.pattern not in PATTERNS:
            raise TeachfitError(f"teacher pattern must be one of {PATTERNS}, got {self.pattern!r}")
        positive = ("speed", "spiral_pitch", "sweep_halfwidth", "max_duration", "record_rate")
        for name in (*positive, "wander_timescale", "press_timescale"):
            if not getattr(self, name) > 0:
                raise TeachfitError(f"teacher {name} must be > 0")
        if not self.hand_smoothing >= 0:
            raise TeachfitError("teacher hand_smoothing must be >= 0")
        if not 0 <= self.press_wander < self.push_force:
            raise TeachfitError("teacher press_wander must be within [0, push_force)")
        if self.min_duration >= self.max_duration:
            raise TeachfitError("teacher min_duration must be below max_duration")


def with_hints(style: TeacherStyle, hints: Mapping[str, object]) -> TeacherStyle:
    """``style`` with ``hints`` (field overrides) on the fields left at their defaults
    (``pattern`` only over the default sweep)."""
    default = TeacherStyle(pattern=style.pattern)
    keep = {k: v for k, v in hints.items() if getattr(style, k) == getattr(default, k)}
    if style.pattern != TeacherStyle.pattern:
        keep.pop("pattern", None)
    return dataclasses.replace(style, **keep) if keep else style


def style_for(
    task: Task, style: TeacherStyle | None = None, robot: Robot | None = None
) -> TeacherStyle:
    """``style`` (default :class:`TeacherStyle`) with the task's ``teacher_hints()`` (a dict of
    field overrides scaled to its cell, e.g. a mesh task's, or ``peg2d``'s sweep scaled to its
    clearance, chamfers and friction) -- or, for a built-in task without them,
    :func:`unchamfered_hints` -- then the ``robot``'s ``teacher_hints(task)`` (the one
    per-robot table, e.g. the FR3's press by feel and its slower hand on tasks searching in
    rz), on the fields left at their defaults (:func:`with_hints`)."""
    hints = getattr(task, "teacher_hints", None)
    given = dict(hints() if hints is not None else unchamfered_hints(task))
    if robot is not None:
        given.update(robot.teacher_hints(task))
    return with_hints(style or TeacherStyle(), given)


def unchamfered_hints(task: Task) -> dict[str, object]:
    """Hints for a task searching yaw whose entry has no chamfer at all (``puzzle``: 0.4 mm
    of play, 0.037 rad of yaw tolerance); ``{}`` for every other task.

    With no chamfer nothing guides the part: it drops only where x, y *and* yaw fit at once.
    The default sweep (rows 2.5 mm apart, a 0.2 rad yaw wiggle) crosses that set about once
    in 200 demonstrations (0/10 recorded). A blind human aligns the part's edges with the
    block's by touch, so the yaw belief and wiggle stay inside the tolerance (as a mesh
    task's hints), and spirals around the believed hole with turns one clearance apart and a
    wander below that: a sub-millimetre sweep over the worst-case region would last minutes.
    """
    p = task.params
    chamfers = [float(getattr(p, f.name)) for f in dataclasses.fields(p) if "chamfer" in f.name]
    clearance = getattr(p, "clearance", None)
    tol = getattr(task, "rz_tolerance", None)
    if "rz" not in task.search_dims or not chamfers or any(chamfers) or not clearance or not tol:
        return {}
    return {
        "pattern": "spiral",
        "spiral_pitch": float(clearance),
        "wander_amplitude": float(clearance) / 4,
        "rz_belief_sigma": float(tol) / 4,
        "rz_wiggle": float(tol) / 3,
    }


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
    def _search_pattern(self, n: int, dt: float) -> np.ndarray:
        """(n, 2) offsets around the belief, at the teacher's speed."""
        st = self.style
        s = st.speed * dt * np.arange(n)  # arc length
        if st.pattern == "spiral":
            # Archimedean spiral r = b theta, arc length ~ b theta^2 / 2
            b = st.spiral_pitch / (2 * np.pi)
            theta = np.sqrt(2 * s / b)
            theta += self.rng.uniform(0, 2 * np.pi)
            r = b * (theta - theta[0])
            return np.column_stack([r * np.cos(theta), r * np.sin(theta)])
        # zig-zag raster: rows spiral_pitch apart, growing width
        width = 0.008
        row_len = width + st.spiral_pitch
        row = np.floor(s / row_len)
        u = s - row * row_len
        x = np.where(row % 2 == 0, u, row_len - u) - width / 2
        y = row * st.spiral_pitch - width / 2
        return np.column_stack([np.clip(x, -width / 2, width / 2), y])

    def _sweep(self, p0: np.ndarray, belief: np.ndarray, n: int, dt: float) -> np.ndarray:
        """(n, 2) raster from ``p0`` across the direction to ``belief`` and past it, world."""
        st = self.style
        span = float(np.linalg.norm(belief - p0))
        u = (belief - p0) / span if span > 1e-9 else np.array([1.0, 0.0])
        v = np.array([-u[1], u[0]]) * self.rng.choice([-1.0, 1.0])
        w, pitch = st.sweep_halfwidth, st.spiral_pitch
        rows = int(np.ceil((span + w) / pitch)) + 1
        corners = [np.zeros(2)]
        side = 1.0
        for k in range(rows):
            corners += [np.array([k * pitch, side * w]), np.array([(k + 1) * pitch, side * w])]
            side = -side
        local = _along_polyline(np.array(corners), st.speed * dt * np.arange(n))
        return p0 + local[:, :1] * u + local[:, 1:] * v

    def _noise(self, n: int, dt: float) -> np.ndarray:
        """(n, 2) slow wander (Ornstein-Uhlenbeck) plus tremor, low-passed over
        ``hand_smoothing`` s when positive, m."""
        st = self.style
        a = np.exp(-dt / st.wander_timescale)
        sd = st.wander_amplitude * np.sqrt(1 - a * a)
        w = np.zeros((n, 2))
        kicks = self.rng.normal(0.0, sd, (n, 2))
        for i in range(1, n):
            w[i] = a * w[i - 1] + kicks[i]
        phase = self.rng.uniform(0, 2 * np.pi, 2)
        t = dt * np.arange(n)
        tremor = st.tremor_amplitude * np.sin(2 * np.pi * st.tremor_frequency * t[:, None] + phase)
        if st.hand_smoothing > 0:  # the same draws through a hand of lower bandwidth
            c = np.exp(-dt / st.hand_smoothing)
            return lfilter([1.0 - c], [1.0, -c], w + tremor, axis=0)
        return w + tremor

    def press(self, n: int, dt: float) -> np.ndarray:
        """(n,) the press's slow deviation from ``push_force`` (N): :func:`press_wander`."""
        return press_wander(self.style, n, dt, self._press_rng)

    def plan(self, start: Pose) -> SetpointTrajectory:
        """The path the teacher's hand intends, world frame, for ``max_duration``."""
        st, task = self.style, self.task
        dt = 1.0 / st.record_rate
        n = int(st.max_duration / dt) + 1
        hole = task.hole2world.pos[:2]
        belief = hole + self.rng.normal(0.0, st.belief_sigma, 2)
        p0 = start.pos[:2]
        if st.pattern == "sweep":
            n_app = min(n - 1, max(2, int(2.0 / dt)))  # turn towards the belief in 2 s
            xy = self._sweep(p0, belief, n, dt)
        else:
            approach_len = float(np.linalg.norm(belief - p0))
            n_app = min(max(2, int(approach_len / st.speed / dt)), n - 1)
            lam = np.linspace(0.0, 1.0, n_app)[:, None]
            approach = p0 + lam * (belief - p0)
            xy = np.concatenate([approach, belief + self._search_pattern(n - n_app, dt)])[:n]
        xy = xy + self._noise(n, dt)
        xy[0] = p0
        t = dt * np.arange(n)
        if self.has_rz:
            period = float(getattr(task, "rz_period", 2 * np.pi))
            rz0 = start.rz
            target = task.hole2world.rz
            target += period * np.round((rz0 - target) / period)
            target += self.rng.normal(0.0, st.rz_belief_sigma)
            rz = np.empty(n)
            rz[:n_app] = rz0 + np.linspace(0.0, 1.0, n_app) * (target - rz0)
            tt = t[n_app:] - t[n_app]
            rz[n_app:] = target + st.rz_wiggle * np.sin(2 * np.pi * st.rz_wiggle_frequency * tt)
            quat = quat_from_rz(rz)
        else:
            quat = np.tile(start.quat, (n, 1))
        pos = np.column_stack([xy, np.full(n, task.surface_z)])
        ff = np.zeros((n, 6))
        ff[:, 2] = -self.press(n, dt)  # added to the follow skill's constant -push_force
        return SetpointTrajectory.from_path(t, pos, quat, wrench_ff=ff, name="teacher-plan")

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
                demos.append(Demonstration(**{**_fields(demo), "name": name}))
                bar.advance(task_id)
        if len(demos) < n:
            raise TeachfitError(
                f"only {len(demos)} of {n} demonstrations succeeded in {limit} attempts; "
                f"discarded: {discarded}"
            )
        return demos, discarded


def follow_config(style: TeacherStyle) -> FollowConfig:
    """How the teacher's hand drives the compliant robot: its arm's stiffness in x-y, the
    follow skill's default z stiffness, its press (and ``press_feel`` loop), no settling, and
    the sideways hold once the part has dropped ``hold_depth``."""
    return FollowConfig(
        stiffness_along=style.arm_stiffness,
        stiffness_across=style.arm_stiffness,
        aligned=False,
        push_force=style.push_force,
        settle_time=0.0,
        press_feel=style.press_feel,
        hold_depth=style.hold_depth,
        tilt=_tilt(style),
    )


def _tilt(style: TeacherStyle) -> TiltConfig | None:
    """The hand's tilted search (``style.tilt`` > 0): it feels the drop at ``hold_depth``
    (0.5 mm without one), slides the part on by up to ``sweep_halfwidth`` or ``tilt_reach``
    (its soft arm pressing the low rim on the hole's far wall as it goes) and turns it
    upright."""
    if style.tilt <= 0.0:
        return None
    drop, reach = style.hold_depth or 5e-4, max(style.sweep_halfwidth, style.tilt_reach)
    return TiltConfig(angle=style.tilt, drop_depth=drop, lateral_reach=reach, stall_lag=reach)


def press_wander(style: TeacherStyle, n: int, dt: float, rng: np.random.Generator) -> np.ndarray:
    """(n,) a teacher's press deviation from ``style.push_force`` every ``dt`` s (N, positive
    presses harder).

    An assumption, not a measurement we can cite for kinesthetic teaching: a person holding a
    steady push of a few newtons drifts by a few percent of it, slowly (force-steadiness
    studies report coefficients of variation of a few percent at low forces, most of the
    fluctuation's power below 1-2 Hz). Modelled as a stationary Ornstein-Uhlenbeck process of
    standard deviation ``style.press_wander`` and time constant ``style.press_timescale``.
    """
    a = np.exp(-dt / style.press_timescale)
    kicks = rng.normal(0.0, style.press_wander * np.sqrt(1 - a * a), n)
    dev = np.empty(n)
    dev[0] = rng.normal(0.0, style.press_wander)  # started stationary
    for i in range(1, n):
        dev[i] = a * dev[i - 1] + kicks[i]
    return dev


def _along_polyline(corners: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points at arc lengths ``s`` along the polyline through ``corners`` (clamped at its end)."""
    seg = np.linalg.norm(np.diff(corners, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    return np.column_stack([np.interp(s, cum, corners[:, j]) for j in range(corners.shape[1])])


def _fields(demo: Demonstration) -> dict[str, object]:
    return {
        "t": demo.t,
        "pos": demo.pos,
        "quat": demo.quat,
        "wrench": demo.wrench,
        "task": demo.task,
        "source": demo.source,
        "frame": demo.frame,
        "child_frame": demo.child_frame,
        "name": demo.name,
        "meta": dict(demo.meta),
    }
