"""What the skill paper's cells share: hole depth, yaw symmetry, tilt and their ground truth.

Johannsmeier et al.'s tasks (``puzzle``, ``key``, ``peg``) are evaluated by its skill protocol
(:class:`~teachfit.tasks.protocols.skill.SkillProtocol`), whose parameters
(:class:`~teachfit.tasks.protocols.skill.SkillProtocolParams`) their own extend. Frames as in
:mod:`teachfit.tasks.base`; lengths in metres, angles in radians.
"""

from __future__ import annotations

import dataclasses
from abc import abstractmethod
from typing import Any

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.tasks.base import Task
from teachfit.tasks.protocols.skill import SkillProtocol, SkillProtocolParams

_SHARED = {f.name for f in dataclasses.fields(SkillProtocolParams)}


class SkillTask(Task):
    """A :class:`Task` of Johannsmeier et al. 2019; ``params`` derive from
    :class:`SkillProtocolParams`.

    Subclasses with ``"rz"`` in ``search_dims`` set ``rz_period`` (the part's rotational
    symmetry, rad) and :attr:`rz_tolerance`.
    """

    params: SkillProtocolParams
    protocol: SkillProtocol
    protocol_type = SkillProtocol

    @property
    @abstractmethod
    def hole_depth(self) -> float:
        """Depth of the hole below its entry (m): a context parameter of the skill."""

    @property
    def rz_tolerance(self) -> float:
        """Largest yaw error (rad, modulo ``rz_period``) an inserted part can have."""
        return float(np.pi)

    def yaw_error(self, tool2world: Pose) -> float:
        """Yaw of the part relative to the hole (rad), wrapped into ``[-period/2, period/2)``."""
        period = float(getattr(self, "rz_period", 2 * np.pi))
        rel = self.hole2world.inverse().compose(tool2world).rz
        return float((rel + period / 2) % period - period / 2)

    def tilt(self, tool2world: Pose) -> float:
        """Angle between the part's axis and the hole axis (rad): how far the part is tilted."""
        rel = self.hole2world.inverse().compose(tool2world)
        axis = rel.rotation.apply([0.0, 0.0, 1.0])
        return float(np.arccos(np.clip(axis[2], -1.0, 1.0)))

    def ground_truth_inserted(self, tool2world: Pose) -> bool:
        """Deeper than :attr:`success_depth`, on the hole axis and (rz tasks) yaw-aligned."""
        if not super().ground_truth_inserted(tool2world):
            return False
        return not self.has_rz or abs(self.yaw_error(tool2world)) < self.rz_tolerance

    def param_table(self) -> list[tuple[str, Any, str]]:
        """Parameter rows, the task's own geometry first, the shared protocol ones after."""
        rows = super().param_table()
        return [r for r in rows if r[0] not in _SHARED] + [r for r in rows if r[0] in _SHARED]
