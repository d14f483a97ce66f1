"""Following a set-point trajectory as a manipulation primitive: search and replay in a graph.

A search trajectory (seed A) or a replayed demonstration is a time-sampled
:class:`~teachfit.core.setpoints.SetpointTrajectory` of desired poses and feed-forward wrenches.
:class:`FollowSetpoints` makes it one node of a skill graph: every command tick at node time
``t`` it sets the set-point to the trajectory's sample ``x_d(t)`` (task frame), commands the
sample's velocity so that the controller extrapolates between ticks, adds the feed-forward
wrench and a constant push ``-push_force`` along the task frame's z (into the surface), and
asks for a stiffness that is high along the direction of motion and low across it (seed A,
Sec. III-D: the part can fall into a hole it passes over)::

    K_xy = k_across I + (k_along - k_across) u u^T,   u = v_xy / |v_xy|

:func:`follow_skill` wraps a trajectory into a one-node skill whose success is the task's
success detector and whose error exits are the time budget (trajectory plus ``settle_time``)
and the force limit, so a search runs through the same engine as every other skill.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from teachfit.control.impedance import aligned_stiffness
from teachfit.core.errors import SkillError
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills.conditions import Any_, Detected, ForceAbove, TimeAbove
from teachfit.skills.graph import Node, Skill
from teachfit.skills.params import SkillParams
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.primitive import Primitive, PrimitiveRun
from teachfit.skills.tilt import LATERAL, LEAD_TIME, LIFT, SEARCH, TiltConfig, TiltState


@dataclass(frozen=True)
class FollowConfig:
    """How a set-point trajectory is followed (N/m, N·m/rad, N, s).

    ``stiffness_along`` / ``stiffness_across`` act in the x-y plane along / across the
    direction of the set-point's motion (``aligned=False``: ``stiffness_along`` everywhere);
    ``push_force`` presses the part onto the surface; ``settle_time`` is how long to wait after
    the trajectory ends; ``max_force`` (N) ends the execution (force limit); ``anchor``:
    ``"frame"`` follows the trajectory as given in the task frame, ``"entry"`` translates it
    so that it starts where the set-point is when the node is entered. ``press_feel`` (s), when
    positive, closes a slow loop on the press as a person pressing by feel does: while in
    contact (measured f_z above half the wanted), the push is corrected by the integral of the
    wanted minus the measured f_z over ``press_feel`` (clipped to half ``push_force``); 0 (the
    default) pushes open loop. ``hold_depth`` (m, None: off): once the TCP has sunk that far
    below its height on entering the node (the part dropped into the hole), the x-y set-point
    stays where the part is and only the push goes on, as a person who feels the part drop
    stops moving it sideways (dragged on, a part caught in a hole with high friction wedges
    instead of sliding in). ``hold_stiffness`` (N/m, None: unchanged): the lateral stiffness,
    the same in every x-y direction, once held, so that the chamfers can centre the pressed
    part (a hand that felt the drop also relaxes sideways). ``tilt`` (None: upright): search
    with the part tilted, and on the drop slide it to the hole's wall and align it upright
    (:mod:`teachfit.skills.tilt`; its align phase is a hold, with ``hold_stiffness``).
    """

    stiffness_along: float = 1500.0
    stiffness_across: float = 150.0
    stiffness_z: float = 100.0
    stiffness_rot: tuple[float, float, float] = (40.0, 40.0, 40.0)
    push_force: float = 6.0
    aligned: bool = True
    settle_time: float = 1.0
    max_force: float = 80.0
    anchor: str = "frame"
    press_feel: float = 0.0
    hold_depth: float | None = None
    hold_stiffness: float | None = None
    tilt: TiltConfig | None = None

    def __post_init__(self) -> None:
        for name in (
            "stiffness_along",
            "stiffness_across",
            "stiffness_z",
            "push_force",
            "settle_time",
            "max_force",
            "press_feel",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise SkillError(f"follow: {name} must be >= 0, got {value}")
        if self.hold_depth is not None and not (
            math.isfinite(self.hold_depth) and self.hold_depth > 0
        ):
            raise SkillError(f"follow: hold_depth must be > 0, got {self.hold_depth}")
        if self.hold_stiffness is not None and not (
            math.isfinite(self.hold_stiffness) and self.hold_stiffness >= 0
        ):
            raise SkillError(f"follow: hold_stiffness must be >= 0, got {self.hold_stiffness}")
        if self.anchor not in ("frame", "entry"):
            raise SkillError(f"follow: anchor must be 'frame' or 'entry', got {self.anchor!r}")

    @property
    def extra_time(self) -> float:
        """Time (s) the follower may need past ``settle_time``: a tilted search's lateral
        and align phases (0 upright)."""
        return 0.0 if self.tilt is None else self.tilt.extra_time


@dataclass(frozen=True)
class FollowSetpoints(Primitive):
    """Follow ``trajectory`` (task frame); see the module docstring. Built in code only."""

    trajectory: SetpointTrajectory
    config: FollowConfig = FollowConfig()
    kind: ClassVar[str] = "follow_setpoints"

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        return _FollowRun(self.trajectory, self.config)

    def describe(self) -> str:
        name = self.trajectory.name or "trajectory"
        return f"follow {name} ({self.trajectory.duration:.1f} s, push {self.config.push_force} N)"

    def refs(self) -> set[str]:
        return set()

    def to_toml(self) -> dict[str, Any]:
        raise SkillError("a follow_setpoints node holds a trajectory and has no TOML form")


class _FollowRun(PrimitiveRun):
    def __init__(self, traj: SetpointTrajectory, cfg: FollowConfig) -> None:
        self.traj, self.cfg = traj, cfg
        self.rot_k = np.asarray(cfg.stiffness_rot, dtype=float)
        self.direction = np.array([1.0, 0.0])
        self.offset = np.zeros(3)
        self.z0 = 0.0
        self.hold: np.ndarray | None = None  # x-y where the part dropped (hold_depth)
        self.diag = np.array([cfg.stiffness_along] * 2 + [cfg.stiffness_z] + list(self.rot_k))
        self.press_correction = 0.0  # N, the felt-press loop's integral (press_feel > 0)
        self.tilt = None if cfg.tilt is None else TiltState(cfg.tilt, traj.pos)
        self.paused = 0.0  # s of node time outside a tilted search's search phase
        self.blend = np.zeros(2)  # m, x-y offset back to the trajectory after a retry
        self.blend_t0, self.blend_time, self.t_last = 0.0, 0.0, 0.0

    def enter(self, pc: Percept) -> None:
        self.direction[:] = (1.0, 0.0)
        self.offset[:] = pc.p_d - self.traj.pos[0] if self.cfg.anchor == "entry" else 0.0
        pc.done = False
        self.press_correction = 0.0
        self.z0, self.hold = float(pc.p[2]), None
        if self.tilt is not None:
            self.tilt.reset(self.z0)
        self.paused, self.blend_time, self.t_last = 0.0, 0.0, 0.0
        if self.tilt is not None and self.tilt.cfg.lead > 0.0:  # the low rim follows the path
            shift = self.tilt.cfg.lead * self.tilt.d
            self.offset[:2] -= shift
            self.blend[:] = shift  # from where the part is, back by the lead over LEAD_TIME
            self.blend_t0, self.blend_time = pc.t_node, LEAD_TIME
        pc.goal[:] = self.traj.pos[-1] + self.offset

    def command(self, pc: Percept, out: MPCommand) -> None:
        cfg = self.cfg
        t_traj = pc.t_node - self.paused
        pos, quat, vel, ff = self.traj.sample(t_traj)
        pc.p_d[:] = pos + self.offset
        if pc.t_node - self.blend_t0 < self.blend_time:
            pc.p_d[:2] += self.blend * (1.0 - (pc.t_node - self.blend_t0) / self.blend_time)
        pc.q_d[:] = quat
        if math.hypot(vel[0], vel[1]) > 1e-6:
            self.direction[:] = vel[:2]
        out.twist[:3] = vel
        out.twist[3:] = 0.0
        out.wrench[:] = ff
        out.wrench[2] -= cfg.push_force
        if cfg.press_feel > 0.0:
            wanted = -out.wrench[2]
            if pc.f[2] > 0.5 * wanted:  # pressing on a surface: not over a hole, not in air
                step = (wanted - pc.f[2]) * pc.dt / cfg.press_feel
                lim = 0.5 * cfg.push_force
                self.press_correction = min(lim, max(-lim, self.press_correction + step))
            out.wrench[2] -= self.press_correction
        if self.tilt is not None:
            self._tilted(pc, out, quat)
        elif cfg.hold_depth is not None:
            if self.hold is None and self.z0 - pc.p[2] >= cfg.hold_depth:
                self.hold = pc.p[:2].copy()
            if self.hold is not None:
                pc.p_d[:2] = self.hold
                out.twist[:2] = 0.0
                out.wrench[:2] = 0.0
        if self.hold is not None and cfg.hold_stiffness is not None:
            k = cfg.hold_stiffness
            out.stiffness_full[:] = aligned_stiffness(
                self.direction, k, k, cfg.stiffness_z, self.rot_k
            )
            out.full = True
        elif cfg.aligned:
            out.stiffness_full[:] = aligned_stiffness(
                self.direction, cfg.stiffness_along, cfg.stiffness_across, cfg.stiffness_z,
                self.rot_k,
            )  # fmt: skip
            out.full = True
        else:
            out.stiffness[:] = self.diag
        pc.done = t_traj >= self.traj.duration

    def _tilted(self, pc: Percept, out: MPCommand, quat: np.ndarray) -> None:
        tilt = self.tilt
        assert tilt is not None
        before = tilt.phase
        if tilt.step(pc) and self.hold is None:
            self.hold = pc.p[:2].copy()
        elapsed, self.t_last = pc.t_node - self.t_last, pc.t_node
        if before != SEARCH:  # the trajectory's clock stood still since the drop
            self.paused += elapsed
        if tilt.phase == SEARCH and before != SEARCH:  # missed: back to the trajectory
            self.hold = None
            self.blend[:] = pc.p[:2] - pc.p_d[:2]
            self.blend_t0 = pc.t_node
            self.blend_time = max(0.2, float(np.hypot(*self.blend)) / tilt.cfg.lateral_speed)
            pc.p_d[:2] = pc.p[:2]
        tilt.orient(pc.q_d, quat, pc.t_node)
        if tilt.phase == LATERAL:
            self.direction[:] = tilt.d
            tilt.lateral(pc, out.twist)
            out.wrench[:2] = 0.0
        elif tilt.phase == LIFT:  # off the top: up, back over it, no push
            t_left = pc.t_node - self.paused  # the trajectory's clock stood still since
            target = self.traj.sample(t_left)[0][:2] + self.offset[:2]  # the drop
            tilt.lift(pc, out.twist[:3], target)
            if math.hypot(out.twist[0], out.twist[1]) > 1e-9:
                self.direction[:] = out.twist[:2]
            out.wrench[:] = 0.0
        elif self.hold is not None:
            pc.p_d[:2] = self.hold
            out.twist[:2] = 0.0
            out.wrench[:2] = 0.0


def follow_skill(
    trajectory: SetpointTrajectory, config: FollowConfig | None = None, name: str = "follow"
) -> Skill:
    """A one-node skill that follows ``trajectory`` until the task's detector fires.

    Its error exits: the time budget ``duration + settle_time`` (plus a tilted search's
    ``extra_time``) and the force limit; the
    execution engine reports them as ``TIMEOUT`` and ``FORCE_LIMIT``.
    """
    cfg = config or FollowConfig()
    horizon = trajectory.duration + cfg.settle_time + cfg.extra_time
    error = Any_((TimeAbove(horizon), ForceAbove(cfg.max_force, axis="norm")))
    node = Node(name, FollowSetpoints(trajectory, cfg), error=error, doc=trajectory.name)
    return Skill(
        name=trajectory.name or name,
        nodes=(node,),
        transitions=(),
        start=name,
        params=SkillParams(),
        success=Detected(),
        error=TimeAbove(horizon + 1.0, scope="skill"),
        frame="the trajectory's frame",
    )
