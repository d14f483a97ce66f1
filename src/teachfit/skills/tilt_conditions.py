"""The conditions that move a tilted search from phase to phase (the transitions of
:mod:`teachfit.skills.tilt_graph`), read from the percept and the execution's
:class:`~teachfit.skills.tilt_context.TiltContext` (heights m, times s)."""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from teachfit.core.errors import SkillError
from teachfit.skills.conditions import Check, Condition
from teachfit.skills.percept import Percept
from teachfit.skills.tilt import LIFT_CLEAR, RETRY, RETRY_SINK
from teachfit.skills.tilt_context import TiltContext, context_of


@dataclass(frozen=True)
class _TiltCondition(Condition):
    """A condition on a tilted search's phase; it holds inside the search's graph only."""

    text: ClassVar[str]

    def compile(self, values: Mapping[str, float]) -> Check:
        return lambda pc: self.holds(context_of(pc), pc)

    @abstractmethod
    def holds(self, ctx: TiltContext, pc: Percept) -> bool:
        """Whether the condition holds now."""

    def describe(self) -> str:
        return self.text

    def to_toml(self) -> dict[str, Any]:
        raise SkillError(f"{self.kind} is a tilted search's condition: no TOML form")


@dataclass(frozen=True)
class DropFelt(_TiltCondition):
    """The TCP sank ``drop_depth`` below the search's reference height."""

    kind: ClassVar[str] = "drop_felt"
    text: ClassVar[str] = "sank drop_depth below the reference height"

    def holds(self, ctx: TiltContext, pc: Percept) -> bool:
        return ctx.reference(pc) - float(pc.p[2]) >= ctx.cfg.drop_depth


@dataclass(frozen=True)
class LeftTop(_TiltCondition):
    """Sliding, the TCP sank more than ``off_depth`` (deeper than any hole gives): the part
    went over the top's outer edge."""

    kind: ClassVar[str] = "left_top"
    text: ClassVar[str] = "sank deeper than off_depth: off the top"

    def holds(self, ctx: TiltContext, pc: Percept) -> bool:
        off = ctx.cfg.off_depth
        return off is not None and ctx.z_top - float(pc.p[2]) > off


@dataclass(frozen=True)
class RodeOut(_TiltCondition):
    """Sliding, the TCP came back up within half ``drop_depth`` of the reference height:
    the rim rode out over the edge (a shallow drop)."""

    kind: ClassVar[str] = "rode_out"
    text: ClassVar[str] = "back up within drop_depth / 2: rode out"

    def holds(self, ctx: TiltContext, pc: Percept) -> bool:
        return ctx.z_top - float(pc.p[2]) < 0.5 * ctx.cfg.drop_depth


@dataclass(frozen=True)
class AtWall(_TiltCondition):
    """Sliding, the set-point leads the TCP along ``d`` by more than ``stall_lag`` (the far
    wall stops the rim), or the slide went ``lateral_reach`` or lasted ``lateral_time``."""

    kind: ClassVar[str] = "at_wall"
    text: ClassVar[str] = "stalled at the wall, or the reach spent"

    def holds(self, ctx: TiltContext, pc: Percept) -> bool:
        cfg, t = ctx.cfg, ctx.time(pc)
        travel = float(np.dot(pc.p[:2] - ctx.origin, ctx.d))
        lead = cfg.lateral_speed * (t - ctx.t0) - travel
        stalled = lead > cfg.stall_lag
        spent = travel >= cfg.lateral_reach or t - ctx.t0 > cfg.lateral_time
        return stalled or spent


@dataclass(frozen=True)
class Missed(_TiltCondition):
    """Upright for ``RETRY`` s and sunk less than ``RETRY_SINK`` since: on the edge."""

    kind: ClassVar[str] = "missed"
    text: ClassVar[str] = "upright and not sinking: missed"

    def holds(self, ctx: TiltContext, pc: Percept) -> bool:
        since = ctx.time(pc) - ctx.t0 - ctx.cfg.align_time
        return since > 0.0 and since > RETRY and ctx.z_aligned - float(pc.p[2]) < RETRY_SINK


@dataclass(frozen=True)
class HighEnough(_TiltCondition):
    """The TCP is ``LIFT_CLEAR`` / 2 above the top's reference height."""

    kind: ClassVar[str] = "high_enough"
    text: ClassVar[str] = "LIFT_CLEAR / 2 above the top"

    def holds(self, ctx: TiltContext, pc: Percept) -> bool:
        return float(pc.p[2]) >= ctx.z_top + 0.5 * LIFT_CLEAR


@dataclass(frozen=True)
class Returned(_TiltCondition):
    """The set-point is back where the trajectory was left and the TCP within
    ``LIFT_CLEAR`` of it."""

    kind: ClassVar[str] = "returned"
    text: ClassVar[str] = "lifted and back where the trajectory was left"

    def holds(self, ctx: TiltContext, pc: Percept) -> bool:
        return ctx.arrived and float(np.hypot(*(pc.p[:2] - ctx.back))) < LIFT_CLEAR


@dataclass(frozen=True)
class AwayFromEdge(_TiltCondition):
    """The TCP is more than ``lateral_reach`` from the edge the part fell over."""

    kind: ClassVar[str] = "away_from_edge"
    text: ClassVar[str] = "lateral_reach from the edge"

    def holds(self, ctx: TiltContext, pc: Percept) -> bool:
        return float(np.hypot(*(pc.p[:2] - ctx.origin))) > ctx.cfg.lateral_reach
