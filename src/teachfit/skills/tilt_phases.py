"""The phases of a tilted search as manipulation primitives, one node each
(:mod:`teachfit.skills.tilt_graph`; the search itself: :mod:`teachfit.skills.tilt`).

Every command each phase follows the trajectory at its clock (the feed-forward, the push,
the felt press: :meth:`~teachfit.skills.tilt_context.TiltContext.track`), advances the clock
(:meth:`~teachfit.skills.tilt_context.TiltContext.tick`: it runs only in the search nodes)
and then sets what the phase overrides: :class:`TiltedSearch` the tilt; the
:class:`TiltPhase` s (:data:`PHASES`) ``slide_to_wall`` the x-y along ``d``,
``align_upright`` the hold and the tilt going to zero, ``lift_off`` and ``back_over_top`` the
lift without the push, ``upright_search`` the upright orientation. What they share lives in
the execution's
:class:`~teachfit.skills.tilt_context.TiltContext`.
"""

from __future__ import annotations

import math
from abc import abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from teachfit.core.errors import SkillError
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills.follower import FollowConfig
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.primitive import Primitive, PrimitiveRun
from teachfit.skills.tilt import LIFT_SPEED
from teachfit.skills.tilt_context import KEY, TiltContext, context_of


class _PhaseRun(PrimitiveRun):
    """A phase for one execution: follow, advance the clock, then :meth:`steer`."""

    #: whether the trajectory's clock runs while this phase commands
    searching: ClassVar[bool] = False

    def __init__(self) -> None:
        self.ctx: TiltContext | None = None

    def enter(self, pc: Percept) -> None:
        self.ctx = context_of(pc)
        self.ctx.set_goal(pc)
        self.begin(self.ctx, pc)

    def begin(self, ctx: TiltContext, pc: Percept) -> None:
        """Mark the phase's start."""
        ctx.t0 = ctx.time(pc)

    def command(self, pc: Percept, out: MPCommand) -> None:
        ctx = self.ctx
        assert ctx is not None, "enter() first"
        quat, t_traj = ctx.track(pc, out, self.searching)
        ctx.tick(pc, self.searching)
        self.steer(ctx, pc, out, quat)
        ctx.follower.stiffness(out)
        pc.done = t_traj >= ctx.traj.duration

    @abstractmethod
    def steer(self, ctx: TiltContext, pc: Percept, out: MPCommand, quat: np.ndarray) -> None:
        """Override the followed set-point where the phase says (``quat``: the
        trajectory's orientation now)."""


class _SearchRun(_PhaseRun):
    searching = True

    def __init__(self, traj: SetpointTrajectory, cfg: FollowConfig) -> None:
        super().__init__()
        self.traj, self.cfg = traj, cfg

    def enter(self, pc: Percept) -> None:
        if self.ctx is None:  # the execution's first entry: the search starts
            self.ctx = TiltContext(self.traj, self.cfg, pc)
            pc.shared[KEY] = self.ctx
            self.ctx.start(pc)
        else:
            super().enter(pc)

    def steer(self, ctx: TiltContext, pc: Percept, out: MPCommand, quat: np.ndarray) -> None:
        ctx.z_top = ctx.reference(pc)
        ramp = ctx.cfg.ramp_time  # from upright to the tilt over the search's first ramp_time
        share = ctx.time(pc) / ramp if ramp > 0.0 else 1.0
        ctx.orient(pc, quat, ctx.full * min(1.0, share))

    def leave(self, pc: Percept) -> None:  # a drop felt: the reference with this tick
        assert self.ctx is not None
        self.ctx.z_top = self.ctx.reference(pc)


class _UprightRun(_PhaseRun):
    searching = True

    def steer(self, ctx: TiltContext, pc: Percept, out: MPCommand, quat: np.ndarray) -> None:
        ctx.z_top = float(pc.p[2])
        ctx.orient(pc, quat, 0.0)

    def leave(self, pc: Percept) -> None:
        context_of(pc).z_top = float(pc.p[2])


class _SlideRun(_PhaseRun):
    def begin(self, ctx: TiltContext, pc: Percept) -> None:
        super().begin(ctx, pc)
        lead = float(np.dot(ctx.planned_xy(pc) - pc.p[:2], ctx.d))  # the spring's pull on
        ctx.origin[:] = pc.p[:2] + max(0.0, lead) * ctx.d  # the part, kept

    def steer(self, ctx: TiltContext, pc: Percept, out: MPCommand, quat: np.ndarray) -> None:
        """The x-y set-point and velocity along ``d`` from the drop; across ``d`` the
        set-point is where the TCP is (no spring across: see *Free across* in
        :mod:`teachfit.skills.tilt`)."""
        ctx.orient(pc, quat, ctx.full)
        d, speed = ctx.d, ctx.cfg.lateral_speed
        ctx.follower.direction[:] = d
        pc.p_d[:2] = ctx.origin + speed * (ctx.time(pc) - ctx.t0) * d
        n0, n1 = -d[1], d[0]
        across = (pc.p[0] - pc.p_d[0]) * n0 + (pc.p[1] - pc.p_d[1]) * n1
        pc.p_d[0] += across * n0
        pc.p_d[1] += across * n1
        out.twist[:2] = speed * d
        out.wrench[:2] = 0.0


class _AlignRun(_PhaseRun):
    def steer(self, ctx: TiltContext, pc: Percept, out: MPCommand, quat: np.ndarray) -> None:
        """Held where the TCP is, the tilt down to zero linearly over ``align_time``."""
        follower, t = ctx.follower, ctx.time(pc)
        if follower.hold is None:
            follower.hold = pc.p[:2].copy()
        if t > ctx.t0 and t - ctx.t0 - ctx.cfg.align_time <= 0.0:  # from the next command
            ctx.z_aligned = float(pc.p[2])  # on: the height as it comes upright
        ctx.orient(pc, quat, ctx.full * max(0.0, 1.0 - (t - ctx.t0) / ctx.cfg.align_time))
        follower.hold_still(pc, out)

    def leave(self, pc: Percept) -> None:  # missed (its only exit): stood on the edge
        ctx = context_of(pc)
        ctx.z_floor = float(pc.p[2])
        other, first = ctx.cfg.retry_angle, ctx.cfg.angle  # the other tilt next time
        if other is not None:
            ctx.tilt_to(other if ctx.full == first else first)


class _LiftRun(_PhaseRun):
    def begin(self, ctx: TiltContext, pc: Percept) -> None:
        super().begin(ctx, pc)
        ctx.arrived = False
        ctx.z_fall, ctx.xy_fall[:] = float(pc.p[2]), pc.p[:2]

    def steer(self, ctx: TiltContext, pc: Percept, out: MPCommand, quat: np.ndarray) -> None:
        """Without the push the set-point rises from the TCP at ``LIFT_SPEED`` (the part's
        unsupported weight pulls it below the set-point, by an amount that depends on the
        part and the stiffness, so it rises until the TCP is high enough)."""
        ctx.orient(pc, quat, ctx.full)
        _back_target(ctx, pc, out)
        ctx.z_lift = ctx.z_fall + LIFT_SPEED * (ctx.time(pc) - ctx.t0)
        pc.p_d[:2], pc.p_d[2], out.twist[2] = ctx.xy_fall, ctx.z_lift, LIFT_SPEED
        out.wrench[:] = 0.0


class _BackRun(_PhaseRun):
    def begin(self, ctx: TiltContext, pc: Percept) -> None:
        ctx.t_lifted = ctx.time(pc)
        ctx.xy_lifted[:] = pc.p[:2]

    def steer(self, ctx: TiltContext, pc: Percept, out: MPCommand, quat: np.ndarray) -> None:
        """At the height reached, x-y at ``LIFT_SPEED`` to where the trajectory was left."""
        ctx.orient(pc, quat, ctx.full)
        target = _back_target(ctx, pc, out)
        pc.p_d[2] = ctx.z_lift
        gap = target - ctx.xy_lifted
        dist = float(np.hypot(gap[0], gap[1]))
        s = LIFT_SPEED * (ctx.time(pc) - ctx.t_lifted)
        ctx.arrived = s >= dist
        if ctx.arrived:
            pc.p_d[:2] = target
        else:
            pc.p_d[:2] = ctx.xy_lifted + gap * (s / dist)
            out.twist[:2] = LIFT_SPEED * gap / dist
        if math.hypot(out.twist[0], out.twist[1]) > 1e-9:
            ctx.follower.direction[:] = out.twist[:2]
        out.wrench[:] = 0.0


def _back_target(ctx: TiltContext, pc: Percept, out: MPCommand) -> np.ndarray:
    """Where the trajectory was left (x-y; its clock stood still since the drop), noted as
    where the lift returns to; the set-point's velocity cleared."""
    t_left = ctx.time(pc) - ctx.paused
    target = ctx.traj.sample(t_left)[0][:2] + ctx.follower.offset[:2]
    ctx.back[:] = target
    out.twist[:3] = 0.0
    return target


#: the phases after the search itself: name -> (its run, what it does)
PHASES: dict[str, tuple[type[_PhaseRun], str]] = {
    "slide_to_wall": (_SlideRun, "slide the low rim on along d, free across it"),
    "align_upright": (_AlignRun, "hold x-y, turn upright over align_time, push on"),
    "lift_off": (_LiftRun, "no push: set-point up until clear of the top"),
    "back_over_top": (_BackRun, "no push: over the top to where the trajectory was left"),
    "upright_search": (_UprightRun, "follow upright (beside the edge the part fell over)"),
}


@dataclass(frozen=True)
class TiltedSearch(Primitive):
    """Follow ``trajectory`` with the part tilted (task frame; ``config.tilt``): the start
    of a tilted search, where the execution's context is made."""

    trajectory: SetpointTrajectory
    config: FollowConfig
    kind: ClassVar[str] = "tilted_search"

    def __post_init__(self) -> None:
        if self.config.tilt is None:
            raise SkillError("tilted_search: the follow config has no tilt")

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        return _SearchRun(self.trajectory, self.config)

    def describe(self) -> str:
        tilt, name = self.config.tilt, self.trajectory.name or "trajectory"
        assert tilt is not None
        return (
            f"follow {name} ({self.trajectory.duration:.1f} s, push {self.config.push_force} N)"
            f" tilted {tilt.angle:g} rad"
        )

    def refs(self) -> set[str]:
        return set()

    def to_toml(self) -> dict[str, Any]:
        raise SkillError("a tilted_search node holds a trajectory and has no TOML form")


@dataclass(frozen=True)
class TiltPhase(Primitive):
    """A phase of a tilted search after the search itself (one of :data:`PHASES`); it runs
    inside the search's graph only."""

    phase: str
    kind: ClassVar[str] = "tilt_phase"

    def __post_init__(self) -> None:
        if self.phase not in PHASES:
            raise SkillError(f"tilt_phase: unknown phase {self.phase!r}; known: {sorted(PHASES)}")

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        return PHASES[self.phase][0]()

    def describe(self) -> str:
        return f"{self.phase}: {PHASES[self.phase][1]}"

    def refs(self) -> set[str]:
        return set()

    def to_toml(self) -> dict[str, Any]:
        raise SkillError("a tilt_phase node runs inside a tilted search only: no TOML form")
