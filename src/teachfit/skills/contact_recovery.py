"""Recoveries of a planned insertion executed in contact: retry along the path, spiral push.

The recovery nodes of :mod:`teachfit.execution.plan_contact`, when the part stopped short:

- :class:`RetryPath` (the L resting on the groove's lip because the capture error put the
  opening elsewhere, or jammed pitched): backs the part out along the path it came
  (collision-free by construction, unlike a straight retreat), shifts the path's remainder
  across the insertion (task x-y) by ``radius`` -- first where the contact pushed the part
  off its set-point, else (and then) along :data:`RING` (the centre: a plain second try;
  opposite directions; the diagonals) -- and follows it again to its end. Plain geometry on
  the plan's own poses: no library plans "the same path, back and shifted".
- :class:`SpiralPush` (a tenon's face on a mortise): presses the part along the insertion
  (task -z, force-controlled: the z set-point follows the part) while its set-point runs an
  outward Archimedean spiral across it, until the part has advanced ``advance`` (the hole
  caught it) -- Johannsmeier et al.'s compliant search, with a spiral instead of a circle.

Timing of a retry: every step at ``speed`` (m/s) or ``angular_speed`` (rad/s), whichever is
slower (:func:`time_poses`, also the timing of the planned path itself).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from teachfit.core.errors import SkillError
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills.follow import FollowConfig, _FollowRun
from teachfit.skills.params import Value, resolve
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.primitive import Primitive, PrimitiveRun

#: unit offsets of successive retries (task x-y): the centre, opposite pairs, axes first
RING = ((0.0, 0.0),) + tuple(
    (math.cos(math.radians(a)), math.sin(math.radians(a)))
    for a in (90, 270, 0, 180, 45, 225, 135, 315)
)


#: lateral deflection (m) of the part from its set-point that gives the first retry its
#: direction: above the tracking noise, below a part lifted onto a wall
DEFLECTION = (0.0005, 0.005)


def time_poses(pos: np.ndarray, quat: np.ndarray, speed: float, angular_speed: float) -> np.ndarray:
    """Times (s) of poses ``(N, 3)`` m, ``(N, 4)`` wxyz: each step at ``speed`` (m/s) or
    ``angular_speed`` (rad/s), whichever takes longer (at least 1 ms)."""
    dots = np.clip(np.abs(np.sum(quat[:-1] * quat[1:], axis=1)), 0.0, 1.0)
    step = np.maximum(
        np.linalg.norm(np.diff(pos, axis=0), axis=1) / speed, 2 * np.arccos(dots) / angular_speed
    )
    return np.concatenate([[0.0], np.cumsum(np.maximum(step, 1e-3))])


def _segment(p0: np.ndarray, q0: np.ndarray, p1: np.ndarray, q1: np.ndarray, n: int):
    """``n`` poses from (p0, q0) to (p1, q1): linear position, normalised-lerp orientation."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    q1 = q1 if float(np.dot(q0, q1)) >= 0 else -q1
    q = (1 - s) * q0 + s * q1
    return (1 - s) * p0 + s * p1, q / np.linalg.norm(q, axis=1, keepdims=True)


def retry_poses(
    path: SetpointTrajectory,
    here: np.ndarray,
    setpoint: tuple[np.ndarray, np.ndarray],
    back: float,
    offset: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Poses of one retry (task frame): from the ``setpoint`` (position, wxyz) to the path
    point nearest the measured position ``here``, back along the path by ``back`` (m of path
    length), across by ``offset`` (m, x-y) and along the shifted path to its end."""
    pos, quat = path.pos, path.quat
    i = int(np.argmin(np.linalg.norm(pos - here, axis=1)))
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pos, axis=0), axis=1))])
    j = int(np.searchsorted(arc, arc[i] - back))
    j = min(j, i)
    shift = np.array([offset[0], offset[1], 0.0])
    p_a, q_a = _segment(setpoint[0], setpoint[1], pos[i], quat[i], 20)
    p_s, q_s = _segment(pos[j], quat[j], pos[j] + shift, quat[j], 10)
    parts_p = [p_a, pos[j : i + 1][::-1], p_s, pos[j:] + shift]
    parts_q = [q_a, quat[j : i + 1][::-1], q_s, quat[j:]]
    return np.concatenate(parts_p), np.concatenate(parts_q)


@dataclass(frozen=True)
class RetryPath(Primitive):
    """Back out along ``path`` and follow its end again shifted; see the module docstring.

    ``back`` (m of path length), ``radius`` (m, the ring of offsets), ``speed`` (m/s) and
    ``angular_speed`` (rad/s); ``config`` the compliance of the follower. Built in code only
    (it holds a trajectory).
    """

    path: SetpointTrajectory
    back: Value = "retry_back"
    radius: Value = "retry_radius"
    speed: Value = "retry_speed"
    angular_speed: Value = 0.5
    config: FollowConfig = FollowConfig()
    kind: ClassVar[str] = "retry_path"

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        back, radius = resolve(self.back, values), resolve(self.radius, values)
        speed, ang = resolve(self.speed, values), resolve(self.angular_speed, values)
        if not (back >= 0 and radius >= 0 and speed > 0 and ang > 0):
            raise SkillError(
                f"retry_path: back and radius must be >= 0, speeds > 0; got {back}, {radius}, "
                f"{speed}, {ang}"
            )
        return _RetryRun(self.path, back, radius, speed, ang, self.config)

    def describe(self) -> str:
        return f"back {self.back} along the path, across by {self.radius}, follow again"

    def to_toml(self) -> dict[str, Any]:
        raise SkillError("a retry_path node holds a trajectory and has no TOML form")


class _RetryRun(PrimitiveRun):
    def __init__(
        self,
        path: SetpointTrajectory,
        back: float,
        radius: float,
        speed: float,
        ang: float,
        cfg: FollowConfig,
    ) -> None:
        self.path, self.back, self.radius, self.speed, self.ang = path, back, radius, speed, ang
        self.cfg = cfg
        self.entries = 0
        self.skip = 0  # 1 once the first retry went where the contact pushed the part
        self.follow: _FollowRun | None = None

    def enter(self, pc: Percept) -> None:
        offset = self.radius * self._direction(pc)
        self.entries += 1
        setpoint = (pc.p_d.copy(), pc.q_d.copy())
        pos, quat = retry_poses(self.path, pc.p.copy(), setpoint, self.back, offset)
        t = time_poses(pos, quat, self.speed, self.ang)
        traj = SetpointTrajectory.from_path(t, pos, quat, name=f"retry {self.entries}")
        self.follow = _FollowRun(traj, self.cfg)
        self.follow.enter(pc)

    def _direction(self, pc: Percept) -> np.ndarray:
        """The first retry goes where the contact pushed the part off its set-point across
        the insertion (if by :data:`DEFLECTION`); the next ones, or all when the part was
        lifted farther (on top of a wall: no direction), follow :data:`RING`."""
        if self.entries == 0:
            dev = pc.p[:2] - pc.p_d[:2]
            norm = float(np.linalg.norm(dev))
            if DEFLECTION[0] <= norm <= DEFLECTION[1]:
                self.skip = 1
                return dev / norm
        return np.asarray(RING[(self.entries - self.skip) % len(RING)])

    def command(self, pc: Percept, out: MPCommand) -> None:
        assert self.follow is not None, "enter() first"
        self.follow.command(pc, out)


@dataclass(frozen=True)
class SpiralPush(Primitive):
    """Push along task -z with ``push`` (N) while the x-y set-point runs an Archimedean spiral
    of ``pitch`` (m between turns) at ``speed`` (m/s) about the entry set-point, out to
    ``radius`` (m) and again from the centre; done once the part is ``advance`` (m) deeper
    than at the entry. ``stiffness`` (N/m, N m/rad, task axes; z unused: force control)."""

    pitch: Value = "spiral_pitch"
    speed: Value = "spiral_speed"
    radius: Value = "spiral_radius"
    push: Value = "spiral_push"
    advance: Value = "spiral_advance"
    #: stiff across (the friction of the pressed face lags the part ~ mu push / k behind the
    #: spiral), soft in rotation (the part aligns itself with the hole once it is caught)
    stiffness: tuple[float, float, float, float, float, float] = (
        3000.0, 3000.0, 300.0, 30.0, 30.0, 30.0,
    )  # fmt: skip
    kind: ClassVar[str] = "spiral_push"

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        names = ("pitch", "speed", "radius", "push", "advance")
        r = {n: resolve(getattr(self, n), values) for n in names}
        if not all(math.isfinite(v) and v > 0 for v in r.values()):
            raise SkillError(f"spiral_push: {', '.join(names)} must be > 0, got {r}")
        return _SpiralRun(r, np.asarray(self.stiffness, dtype=float))

    def describe(self) -> str:
        return f"spiral of pitch {self.pitch} out to {self.radius}, push {self.push}"


class _SpiralRun(PrimitiveRun):
    def __init__(self, r: dict[str, float], stiffness: np.ndarray) -> None:
        self.pitch, self.speed, self.radius = r["pitch"], r["speed"], r["radius"]
        self.push, self.advance, self.k = r["push"], r["advance"], stiffness
        # arc length of one sweep out to the radius: s = pitch theta^2 / (4 pi)
        self.theta_max = 2 * math.pi * self.radius / self.pitch
        self.s_max = self.pitch * self.theta_max**2 / (4 * math.pi)
        self.centre = np.zeros(2)
        self.z0 = 0.0

    def _xy(self, t: float) -> np.ndarray:
        s = (self.speed * t) % self.s_max
        theta = math.sqrt(4 * math.pi * s / self.pitch)
        r = self.pitch * theta / (2 * math.pi)
        return self.centre + r * np.array([math.cos(theta), math.sin(theta)])

    def enter(self, pc: Percept) -> None:
        self.centre[:] = pc.p_d[:2]
        self.z0 = float(pc.p[2])
        pc.done = False

    def command(self, pc: Percept, out: MPCommand) -> None:
        nxt = self._xy(pc.t_node + pc.dt)
        out.twist[:2] = (nxt - pc.p_d[:2]) / pc.dt
        pc.p_d[2] = pc.p[2]  # force control along z: only the push presses
        out.twist[2:] = 0.0
        out.wrench[:] = 0.0
        out.wrench[2] = -self.push
        out.stiffness[:] = self.k
        pc.done = float(pc.p[2]) < self.z0 - self.advance
