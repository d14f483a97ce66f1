"""One execution of a run, as a run log keeps it (:mod:`teachfit.execution.recording`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from teachfit.core.geometry import Pose
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.engine import ExecutionResult
from teachfit.skills.graph import Skill


@dataclass(frozen=True)
class Episode:
    """One execution of a run: the engine's ``result``, where it started (``start``, world
    frame), the planned set-points (``planned``, searches) and ``primitives`` (node name ->
    what the node's primitive does, skills)."""

    result: ExecutionResult
    start: Pose | None = None
    planned: SetpointTrajectory | None = None
    primitives: Mapping[str, str] = field(default_factory=dict)
    name: str = ""

    @classmethod
    def of_skill(cls, result: ExecutionResult, skill: Skill, start: Pose | None = None) -> Episode:
        """An episode of ``skill`` (its nodes' primitives recorded, the recovery node too)."""
        nodes = skill.nodes + ((skill.recovery,) if skill.recovery is not None else ())
        return cls(result, start, primitives={n.name: n.primitive.describe() for n in nodes})
