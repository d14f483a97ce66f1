"""Manipulation primitives (MPs): desired twist and feed-forward wrench in the task frame.

Johannsmeier et al. 2019 (Sec. III): an MP maps the percept ``x`` and its parameters to a desired
twist ``xdot_d = f_t(x, P_t)`` and a feed-forward wrench ``F_d = f_w(x, P_w)``, both in the task
frame. Here an MP also states the Cartesian stiffness (diagonal, task axes) it wants, which
the controller uses as its (initial) impedance.

Each kind is a frozen spec whose fields are :data:`~teachfit.skills.params.Value` s;
:meth:`Primitive.compile` resolves them once per execution into a :class:`PrimitiveRun`
whose :meth:`~PrimitiveRun.enter` latches the entry state and whose
:meth:`~PrimitiveRun.command` fills an :class:`~teachfit.skills.percept.MPCommand` each
command tick without allocating.

The executor integrates the twist over one command period ``dt`` to move the set-point
``(p_d, q_d)``: ``p_d += v dt``, ``q_d = exp(w dt) q_d`` (task frame). Profile-following
primitives therefore emit the mean velocity over the coming period,
``(s(t + dt) - s(t)) / dt`` times the path, so the set-point lands exactly on the goal.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import Field, dataclass, fields
from typing import Any, ClassVar

import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.core.errors import SkillError
from teachfit.core.geometry import (
    quat_conj_into,
    quat_from_rz,
    quat_mul_into,
    quat_to_rotvec_into,
    rotation_to_wxyz,
    yaw_of,
)
from teachfit.skills.params import Value, ref_name, resolve
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.profile import Trapezoid, synchronized

Vec3V = tuple[Value, Value, Value]
Vec6V = tuple[Value, Value, Value, Value, Value, Value]


class PrimitiveRun(ABC):
    """A primitive with its parameters resolved, for one execution."""

    @abstractmethod
    def enter(self, pc: Percept) -> None:
        """Called when the node becomes active (``pc.p_d``/``pc.q_d`` hold the set-point)."""

    @abstractmethod
    def command(self, pc: Percept, out: MPCommand) -> None:
        """Fill ``out`` (task frame) for the command period starting at ``pc.t_node``."""

    def leave(self, pc: Percept) -> None:
        """Called when a transition leaves the node (before the next one is entered); by
        default nothing happens."""
        return None


class Primitive(ABC):
    """A primitive spec (see the module docstring)."""

    kind: ClassVar[str]
    #: set by ``@dataclass`` on every concrete kind (what :func:`dataclasses.fields` reads)
    __dataclass_fields__: ClassVar[dict[str, Field[Any]]]

    @abstractmethod
    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        """Resolve the parameters; invalid resolved values raise :class:`SkillError`."""

    @abstractmethod
    def describe(self) -> str:
        """One line for figures and listings."""

    def refs(self) -> set[str]:
        """Names of the parameters this primitive uses."""
        out: set[str] = set()
        for f in fields(self):
            val = getattr(self, f.name)
            for v in val if isinstance(val, tuple) else (val,):
                if isinstance(v, int | float | str) and not isinstance(v, bool):
                    if (n := ref_name(v)) is not None:
                        out.add(n)
        return out

    def to_toml(self) -> dict[str, Any]:
        out: dict[str, Any] = {"primitive": self.kind}
        for f in fields(self):
            val = getattr(self, f.name)
            if val is not None:
                out[f.name] = list(val) if isinstance(val, tuple) else val
        return out


def _positive(name: str, value: float) -> float:
    if not (math.isfinite(value) and value > 0):
        raise SkillError(f"{name} must be > 0, got {value}")
    return value


def _nonneg(name: str, value: float) -> float:
    if not (math.isfinite(value) and value >= 0):
        raise SkillError(f"{name} must be >= 0, got {value}")
    return value


def _vec(values: Mapping[str, float], vec: tuple[Value, ...], name: str) -> np.ndarray:
    out = np.array([resolve(v, values) for v in vec], dtype=float)
    if not np.all(np.isfinite(out)):
        raise SkillError(f"{name} must be finite, got {out.tolist()}")
    return out


def _stiffness(values: Mapping[str, float], vec: Vec6V) -> np.ndarray:
    k = _vec(values, vec, "stiffness")
    if np.any(k < 0):
        raise SkillError(f"stiffness must be >= 0, got {k.tolist()}")
    return k


def _quat_rz_ry(yaw: float, tilt: float, roll: float = 0.0) -> np.ndarray:
    """``Rz(yaw) Ry(tilt) Rx(roll)`` (rad, intrinsic z, y, x) as a quaternion (w, x, y, z)."""
    return rotation_to_wxyz(Rotation.from_euler("ZYX", [yaw, tilt, roll]), canonical=False)


def _check_len(name: str, vec: tuple[Value, ...] | None, n: int) -> None:
    if vec is not None and len(vec) != n:
        raise SkillError(f"{name} needs {n} values, got {len(vec)}")


@dataclass(frozen=True)
class MoveTo(Primitive):
    """Move the set-point to a goal pose along a synchronised trapezoidal profile.

    ``goal`` (m, task frame; ``relative=True``: an offset from the entry set-point; ``None``:
    keep the position). The goal orientation is ``Rz(yaw) Ry(tilt) Rx(roll)`` in the
    task frame (``None``: keep the orientation); with ``rz_period > 0`` the yaw goal is
    shifted by whole periods to the one nearest the entry yaw (symmetric parts). Translation
    and rotation share one time scaling within ``v_max``, ``a_max`` (m/s, m/s²) and
    ``w_max``, ``dw_max`` (rad/s, rad/s²); ``speed_factor`` scales time, i.e. speeds by it
    and accelerations by its square. ``push`` (N) is a feed-forward force along the task -z.
    """

    goal: Vec3V | None = None
    relative: bool = False
    yaw: Value | None = None
    tilt: Value | None = None
    roll: Value = 0.0
    rz_period: Value = 0.0
    v_max: Value = 0.05
    a_max: Value = 0.5
    w_max: Value = 0.5
    dw_max: Value = 5.0
    speed_factor: Value = 1.0
    push: Value = 0.0
    stiffness: Vec6V = (2000.0, 2000.0, 2000.0, 60.0, 60.0, 60.0)
    kind: ClassVar[str] = "move_to"

    def __post_init__(self) -> None:
        _check_len("goal", self.goal, 3)
        _check_len("stiffness", self.stiffness, 6)
        if (self.yaw is None) != (self.tilt is None):
            raise SkillError("move_to: give both yaw and tilt, or neither (keep orientation)")

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        sf = _positive("speed_factor", resolve(self.speed_factor, values))
        return _MoveToRun(
            goal=None if self.goal is None else _vec(values, self.goal, "goal"),
            relative=self.relative,
            q_goal=None
            if self.yaw is None or self.tilt is None
            else _quat_rz_ry(
                resolve(self.yaw, values), resolve(self.tilt, values), resolve(self.roll, values)
            ),
            rz_period=_nonneg("rz_period", resolve(self.rz_period, values)),
            v=_positive("v_max", resolve(self.v_max, values)) * sf,
            a=_positive("a_max", resolve(self.a_max, values)) * sf * sf,
            w=_positive("w_max", resolve(self.w_max, values)) * sf,
            dw=_positive("dw_max", resolve(self.dw_max, values)) * sf * sf,
            push=_nonneg("push", resolve(self.push, values)),
            stiffness=_stiffness(values, self.stiffness),
        )

    def describe(self) -> str:
        where = (
            "keep position"
            if self.goal is None
            else (f"{'by' if self.relative else 'to'} ({', '.join(map(str, self.goal))})")
        )
        rot = "" if self.yaw is None else f", yaw {self.yaw}, tilt {self.tilt}"
        return f"trapezoid {where}{rot}"


class _MoveToRun(PrimitiveRun):
    def __init__(
        self,
        *,
        goal: np.ndarray | None,
        relative: bool,
        q_goal: np.ndarray | None,
        rz_period: float,
        v: float,
        a: float,
        w: float,
        dw: float,
        push: float,
        stiffness: np.ndarray,
    ) -> None:
        self.goal_spec, self.relative, self.q_goal_spec = goal, relative, q_goal
        self.rz_period, self.v, self.a, self.w, self.dw = rz_period, v, a, w, dw
        self.push, self.k = push, stiffness
        self.p0 = np.zeros(3)
        self.dp = np.zeros(3)
        self.rotvec = np.zeros(3)
        self.profile = Trapezoid(0.0, 1.0, 1.0)

    def enter(self, pc: Percept) -> None:
        self.p0[:] = pc.p_d
        goal = (
            self.p0.copy()
            if self.goal_spec is None
            else (self.goal_spec + self.p0 if self.relative else self.goal_spec.copy())
        )
        self.dp[:] = goal - self.p0
        pc.goal[:] = goal
        self.rotvec[:] = 0.0
        if self.q_goal_spec is not None:
            q_goal = self.q_goal_spec.copy()
            if self.rz_period > 0:  # nearest symmetric yaw to the entry yaw
                k = round((yaw_of(pc.q_d) - yaw_of(q_goal)) / self.rz_period)
                quat_mul_into(q_goal, quat_from_rz(k * self.rz_period), self.q_goal_spec)
            # rotation vector r (task frame) with exp(r) q_d = q_goal
            dq, inv = np.zeros(4), np.zeros(4)
            quat_conj_into(inv, pc.q_d)
            quat_mul_into(dq, q_goal, inv)
            quat_to_rotvec_into(self.rotvec, dq)
        dist = float(np.linalg.norm(self.dp))
        ang = float(np.linalg.norm(self.rotvec))
        self.profile = synchronized((dist, ang), (self.v, self.w), (self.a, self.dw))
        pc.done = self.profile.duration == 0.0

    def command(self, pc: Percept, out: MPCommand) -> None:
        prof, t, dt = self.profile, pc.t_node, pc.dt
        ds = (prof.position(t + dt) - prof.position(t)) / dt
        out.twist[:3] = self.dp * ds
        out.twist[3:] = self.rotvec * ds
        out.wrench[:] = 0.0
        out.wrench[2] = -self.push
        out.stiffness[:] = self.k
        pc.done = t + dt >= prof.duration


@dataclass(frozen=True)
class Move(Primitive):
    """Move the set-point at constant velocity ``speed * speed_factor`` (m/s) along the unit
    ``direction`` (task frame) -- until a transition fires -- while pushing ``push`` (N)
    along the task -z. Used for "move down until contact" and "move sideways until
    constrained"."""

    direction: Vec3V = (0.0, 0.0, -1.0)
    speed: Value = 0.01
    speed_factor: Value = 1.0
    push: Value = 0.0
    stiffness: Vec6V = (2000.0, 2000.0, 2000.0, 60.0, 60.0, 60.0)
    kind: ClassVar[str] = "move"

    def __post_init__(self) -> None:
        _check_len("direction", self.direction, 3)
        _check_len("stiffness", self.stiffness, 6)

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        d = _vec(values, self.direction, "direction")
        n = float(np.linalg.norm(d))
        if n < 1e-9:
            raise SkillError("move: direction must not be zero")
        speed = _positive("speed", resolve(self.speed, values))
        speed *= _positive("speed_factor", resolve(self.speed_factor, values))
        return _MoveRun(
            d / n * speed,
            _nonneg("push", resolve(self.push, values)),
            _stiffness(values, self.stiffness),
        )

    def describe(self) -> str:
        d = ", ".join(f"{v:g}" if isinstance(v, float | int) else v for v in self.direction)
        return f"move ({d}) at {self.speed}" + (f", push {self.push}" if self.push else "")


class _MoveRun(PrimitiveRun):
    def __init__(self, vel: np.ndarray, push: float, stiffness: np.ndarray) -> None:
        self.vel, self.push, self.k = vel, push, stiffness

    def enter(self, pc: Percept) -> None:
        pc.done = False

    def command(self, pc: Percept, out: MPCommand) -> None:
        out.twist[:3] = self.vel
        out.twist[3:] = 0.0
        out.wrench[:] = 0.0
        out.wrench[2] = -self.push
        out.stiffness[:] = self.k


@dataclass(frozen=True)
class Insert(Primitive):
    """Push with ``force`` (N) along the task -z while the set-point sinks at ``sink``
    (m/s) to ``depth`` (m below the task x-y plane), superposing oscillations:

        dp_xy(t) = a_t rho(t) (sin 2 pi f_t t, cos 2 pi f_t t)   (a circle, m, Hz)
        d rz(t)  = a_r sin 2 pi f_r t                           (rad, Hz)

    about the entry set-point, with ``rho(t) = min(1, f_t t)`` growing the circle from the
    entry point over one period. The wiggle lets a part with lateral and angular error slip
    into the hole (Johannsmeier et al. 2019, MP 5).

    The push fades with the part's speed into the hole ``v`` (m/s, along the task -z):

        F(v) = force clip(2 - v / v_press, 0, 1)

    full up to ``v_press``, none from ``2 v_press``. A part that comes free in the hole is not
    driven on: pushed with 20 N through the FR3's 7 kg along the axis it slid 0.2 m/s at the
    success depth, tilted against the wall, and a real arm's reset would have to brake that
    within the millimetres left to the hole's bottom. A jammed part (v near 0) gets the
    whole push.
    """

    force: Value = 10.0
    depth: Value = 0.01
    sink: Value = 0.01
    a_t: Value = 0.0
    f_t: Value = 1.0
    a_r: Value = 0.0
    f_r: Value = 1.0
    v_press: Value = math.inf
    stiffness: Vec6V = (500.0, 500.0, 300.0, 40.0, 40.0, 20.0)
    kind: ClassVar[str] = "insert"

    def __post_init__(self) -> None:
        _check_len("stiffness", self.stiffness, 6)

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        r = {
            f.name: resolve(getattr(self, f.name), values)
            for f in fields(self)
            if f.name != "stiffness"
        }
        for name in ("force", "depth", "a_t", "a_r"):
            _nonneg(name, r[name])
        for name in ("sink", "f_t", "f_r", "v_press"):
            _positive(name, r[name])
        return _InsertRun(r, _stiffness(values, self.stiffness))

    def describe(self) -> str:
        fade = "" if self.v_press == math.inf else f", fading above {self.v_press}"
        return (
            f"push {self.force} to depth {self.depth}{fade}; osc. a_t {self.a_t} @ {self.f_t}, "
            f"a_r {self.a_r} @ {self.f_r}"
        )


class _InsertRun(PrimitiveRun):
    def __init__(self, r: dict[str, float], stiffness: np.ndarray) -> None:
        self.force, self.depth, self.sink = r["force"], r["depth"], r["sink"]
        self.a_t, self.f_t, self.w_t = r["a_t"], r["f_t"], 2 * math.pi * r["f_t"]
        self.a_r, self.w_r = r["a_r"], 2 * math.pi * r["f_r"]
        self.v_press = r["v_press"]
        self.k = stiffness
        self.z0 = 0.0

    def enter(self, pc: Percept) -> None:
        self.z0 = float(pc.p_d[2])
        pc.goal[:] = (pc.p_d[0], pc.p_d[1], -self.depth)
        pc.done = False

    def command(self, pc: Percept, out: MPCommand) -> None:
        t0, t1, dt = pc.t_node, pc.t_node + pc.dt, pc.dt
        wt, wr = self.w_t, self.w_r
        # mean velocities over [t0, t1] of the oscillation offsets (exact increments)
        r0 = self.a_t * min(1.0, self.f_t * t0)
        r1 = self.a_t * min(1.0, self.f_t * t1)
        out.twist[0] = (r1 * math.sin(wt * t1) - r0 * math.sin(wt * t0)) / dt
        out.twist[1] = (r1 * math.cos(wt * t1) - r0 * math.cos(wt * t0)) / dt
        z_next = max(-self.depth, self.z0 - self.sink * t1)
        out.twist[2] = (z_next - pc.p_d[2]) / dt
        out.twist[3] = out.twist[4] = 0.0
        out.twist[5] = self.a_r * (math.sin(wr * t1) - math.sin(wr * t0)) / dt
        out.wrench[:] = 0.0
        fade = min(1.0, max(0.0, 2.0 + pc.v[2] / self.v_press))  # pc.v[2] < 0: into the hole
        out.wrench[2] = -self.force * fade
        out.stiffness[:] = self.k


PRIMITIVES: dict[str, type[MoveTo | Move | Insert]] = {c.kind: c for c in (MoveTo, Move, Insert)}


def primitive_from_toml(data: Mapping[str, Any]) -> Primitive:
    """A primitive from its TOML table (``primitive = "<kind>"`` plus its fields)."""
    kind = data.get("primitive")
    if kind not in PRIMITIVES:
        raise SkillError(f"unknown primitive {kind!r}; known: {sorted(PRIMITIVES)}")
    cls = PRIMITIVES[kind]
    known = {f.name for f in fields(cls)}
    kwargs: dict[str, Any] = {  # raw TOML values
        k: tuple(v) if isinstance(v, list) else v for k, v in data.items() if k != "primitive"
    }
    unknown = sorted(set(kwargs) - known)
    if unknown:
        raise SkillError(f"primitive {kind!r}: unknown field(s) {unknown}; known: {sorted(known)}")
    return cls(**kwargs)
