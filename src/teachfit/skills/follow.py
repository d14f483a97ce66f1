"""Following a set-point trajectory as a manipulation primitive: search and replay in a graph.

A search trajectory (Ehlers et al. 2019) or a replayed demonstration is a time-sampled
:class:`~teachfit.core.setpoints.SetpointTrajectory` of desired poses and feed-forward wrenches.
:class:`FollowSetpoints` makes it one node of a skill graph: every command tick at node time
``t`` it sets the set-point to the trajectory's sample ``x_d(t)`` (task frame), commands the
sample's velocity so that the controller extrapolates between ticks, adds the feed-forward
wrench and a constant push ``-push_force`` along the task frame's z (into the surface), and
asks for a stiffness that is high along the direction of motion and low across it (Ehlers et al.
2019, Sec. III-D: the part can fall into a hole it passes over)::

    K_xy = k_across I + (k_along - k_across) u u^T,   u = v_xy / |v_xy|

:func:`follow_skill` wraps a trajectory into a one-node skill whose success is the task's
success detector and whose error exits are the time budget (trajectory plus ``settle_time``)
and the force limit, so a search runs through the same engine as every other skill; with a
``tilt`` the search is a graph of its own, one node per phase (:mod:`teachfit.skills.tilt_graph`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from teachfit.core.errors import SkillError
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills.conditions import Any_, Detected, ForceAbove, TimeAbove
from teachfit.skills.follower import FollowConfig, Follower
from teachfit.skills.graph import Node, Skill
from teachfit.skills.params import SkillParams
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.primitive import Primitive, PrimitiveRun
from teachfit.skills.tilt_graph import tilted_search_graph

__all__ = ["FollowConfig", "FollowSetpoints", "follow_skill"]


@dataclass(frozen=True)
class FollowSetpoints(Primitive):
    """Follow ``trajectory`` (task frame) upright; see the module docstring. Built in code
    only; a tilted follower is a graph of its own (:func:`follow_skill`)."""

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
        if cfg.tilt is not None:
            raise SkillError(
                "a tilted follower is a skill graph of its own (one node per phase): "
                "build it with follow_skill"
            )
        self.traj, self.cfg = traj, cfg
        self.follower = Follower(traj, cfg)

    def enter(self, pc: Percept) -> None:
        self.follower.start(pc)
        pc.goal[:] = self.traj.pos[-1] + self.follower.offset

    def command(self, pc: Percept, out: MPCommand) -> None:
        follower, depth = self.follower, self.cfg.hold_depth
        follower.track(pc, out, pc.t_node)
        if depth is not None:
            if follower.hold is None and follower.z0 - pc.p[2] >= depth:
                follower.hold = pc.p[:2].copy()
            if follower.hold is not None:
                follower.hold_still(pc, out)
        follower.stiffness(out)
        pc.done = pc.t_node >= self.traj.duration


def _follow_error(trajectory: SetpointTrajectory, cfg: FollowConfig, scope: str) -> Any_:
    """The time budget (``duration + settle_time`` plus a tilted search's ``extra_time``)
    and the force limit."""
    horizon = trajectory.duration + cfg.settle_time + cfg.extra_time
    return Any_((TimeAbove(horizon, scope=scope), ForceAbove(cfg.max_force, axis="norm")))


def follow_skill(
    trajectory: SetpointTrajectory, config: FollowConfig | None = None, name: str = "follow"
) -> Skill:
    """A skill that follows ``trajectory`` until the task's detector fires: one node, or
    with a ``tilt`` one node per phase of the tilted search
    (:func:`~teachfit.skills.tilt_graph.tilted_search_graph`).

    Its error exits: the time budget ``duration + settle_time`` (plus a tilted search's
    ``extra_time``) and the force limit; the
    execution engine reports them as ``TIMEOUT`` and ``FORCE_LIMIT``.
    """
    cfg = config or FollowConfig()
    horizon = trajectory.duration + cfg.settle_time + cfg.extra_time
    if cfg.tilt is not None:  # the phases share the budget: counted from the skill's start
        nodes, transitions = tilted_search_graph(
            trajectory, cfg, _follow_error(trajectory, cfg, "skill")
        )
    else:
        error = _follow_error(trajectory, cfg, "node")
        nodes = (Node(name, FollowSetpoints(trajectory, cfg), error=error, doc=trajectory.name),)
        transitions = ()
    return Skill(
        name=trajectory.name or name,
        nodes=nodes,
        transitions=transitions,
        start=nodes[0].name,
        params=SkillParams(),
        success=Detected(),
        error=TimeAbove(horizon + 1.0, scope="skill"),
        frame="the trajectory's frame",
    )
