"""Johannsmeier et al.'s start protocol and taught hole pose, shared by ``puzzle``, ``key`` and
``peg``.

Johannsmeier et al. 2019 (Johannsmeier et al., ICRA 2019) evaluates every trial from *four slightly
different start poses* above the hole, and the skill only knows the hole pose a human taught it
(with an error below a millimetre). :class:`SkillProtocol` provides both:

* :meth:`SkillProtocol.skill_starts` / ``protocol_starts("skill", n, rng)``: ``n`` (4 in the
  paper) TCP poses ``approach_height`` above the surface, ``start_offset`` from the hole axis in
  evenly spread directions (a random common phase) and yaw within ``+-start_yaw`` of the hole's,
  deterministic for a generator state.
* :meth:`SkillProtocol.estimated_hole`: the hole frame with Gaussian errors in x, y
  (``hole_pos_sigma``) and yaw (``hole_yaw_sigma``), the skill's context parameter.

Frames as in :mod:`teachfit.tasks.base`: world z up, the hole frame at the entry centre.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.tasks.params import TaskParams, doc_field
from teachfit.tasks.protocols.base import Protocol

if TYPE_CHECKING:
    from teachfit.tasks.geometry.skill import SkillTask


@dataclass(frozen=True)
class SkillProtocolParams(TaskParams):
    """Start protocol, taught-hole error and friction shared by the skill paper's tasks.

    Lengths in metres, angles in radians. Subclasses add the geometry and may change defaults.
    """

    approach_height: float = doc_field(
        "height of the skill starts above the surface (m)", 0.025, above=0
    )
    start_offset: float = doc_field(
        "lateral offset of the skill starts from the hole (m)", 0.002, at_least=0
    )
    start_yaw: float = doc_field(
        "skill starts draw yaw within +-start_yaw of the hole (rad)", 0.0, at_least=0
    )
    hole_pos_sigma: float = doc_field(
        "std of the taught hole position, per axis (m)", 0.0005, at_least=0
    )
    hole_yaw_sigma: float = doc_field("std of the taught hole yaw (rad)", 0.0, at_least=0)
    start_deviation: float = doc_field(
        "deliberate deviation of each start's hole estimate from the taught one (m)",
        0.0,
        at_least=0,
    )
    demo_offset: float = doc_field(
        "distance of the blind teacher's start from the hole (m)", 0.02, above=0
    )
    friction: float = doc_field("sliding friction coefficient part/fixture", 0.3, at_least=0)

    def check(self) -> None:
        super().check()
        self.require(
            self.start_yaw < np.pi / 4, f"start_yaw must be below pi/4, got {self.start_yaw}"
        )


class SkillProtocol(Protocol):
    """Johannsmeier et al.'s ``"skill"`` starts above the hole and the taught (estimated) hole
    pose."""

    task: SkillTask
    names: ClassVar[tuple[str, ...]] = ("skill",)

    def teacher_start(self, rng: np.random.Generator) -> Pose:
        """On the surface ``demo_offset`` from the hole in a random direction (hole frame).

        Tasks searching rz also draw a yaw within ``+-start_yaw`` of the hole's.
        """
        task, p = self.task, self.task.params
        ang = rng.uniform(0.0, 2 * np.pi)
        yaw = rng.uniform(-p.start_yaw, p.start_yaw) if task.has_rz else 0.0
        off = p.demo_offset * np.array([np.cos(ang), np.sin(ang)])
        return in_frame(task.hole2world, off, task.surface_z - task.hole2world.pos[2], yaw)

    def skill_starts(self, rng: np.random.Generator, around: Pose | None = None) -> list[Pose]:
        """The paper's four slightly different start poses of one trial.

        ``around`` is the frame they are spread around (e.g. :meth:`estimated_hole`); by
        default the true hole frame. See :meth:`paper_starts`.
        """
        return self.spread_starts(4, rng, around)

    def paper_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None
    ) -> list[Pose]:
        """``"skill"``: ``n`` TCP poses ``approach_height`` above the surface, ``start_offset``
        from the hole axis in directions ``2 pi k / n`` plus one random phase, yaw (relative to
        the hole) uniform within ``+-start_yaw``; the paper uses ``n = 4``. ``demo_start`` is
        not used."""
        del protocol, demo_start
        return self.spread_starts(n, rng, None)

    def estimated_hole(
        self,
        rng: np.random.Generator,
        pos_sigma: float | None = None,
        yaw_sigma: float | None = None,
    ) -> Pose:
        """The hole pose as a human taught it: the true hole frame with Gaussian errors.

        x and y each get ``N(0, pos_sigma)`` (m, default ``hole_pos_sigma``), the yaw
        ``N(0, yaw_sigma)`` (rad, default ``hole_yaw_sigma``); z and tilt are exact (the skill
        finds the surface by contact).
        """
        p = self.task.params
        ps = p.hole_pos_sigma if pos_sigma is None else pos_sigma
        ys = p.hole_yaw_sigma if yaw_sigma is None else yaw_sigma
        if ps < 0 or ys < 0:
            raise TaskError(f"estimated_hole sigmas must be >= 0, got {ps}, {ys}")
        dx, dy = rng.normal(0.0, ps, 2) if ps > 0 else (0.0, 0.0)
        dyaw = float(rng.normal(0.0, ys)) if ys > 0 else 0.0
        return self.task.hole2world.compose(Pose.from_xyz_rz(dx, dy, 0.0, dyaw))

    def start_frames(self, around: Pose, starts: list[Pose]) -> list[Pose]:
        """Per start, the hole estimate the skill runs with: ``around`` (the taught hole)
        moved ``start_deviation`` along the start's own direction from the (true) hole axis.

        Johannsmeier et al. 2019 applies a "deliberate initial pose deviation" to the four starts of
        a trial (none on the key, "due to the very small hole"): the skill then looks for the hole
        that far from where it is, in a different direction each start. Without deviation
        (or for a start on the axis) every start gets ``around``.
        """
        dev = self.task.params.start_deviation
        out = []
        for s in starts:
            rel = self.task.hole2world.inverse().compose(s).pos[:2]
            norm = float(np.hypot(*rel))
            if dev == 0 or norm < 1e-12:
                out.append(around)
                continue
            d = dev * rel / norm
            out.append(around.compose(Pose.from_xyz_rz(float(d[0]), float(d[1]), 0.0, 0.0)))
        return out

    def spread_starts(self, n: int, rng: np.random.Generator, around: Pose | None) -> list[Pose]:
        """``n`` starts evenly spread around the frame ``around`` (default: the true hole)."""
        task, p = self.task, self.task.params
        phase = rng.uniform(0.0, 2 * np.pi)
        ang = phase + 2 * np.pi * np.arange(n) / n
        yaw = rng.uniform(-p.start_yaw, p.start_yaw, n) if task.has_rz else np.zeros(n)
        frame = task.hole2world if around is None else around
        height = task.surface_z - frame.pos[2] + p.approach_height
        return [
            in_frame(frame, p.start_offset * np.array([np.cos(a), np.sin(a)]), height, float(y))
            for a, y in zip(ang, yaw, strict=True)
        ]


def in_frame(frame: Pose, xy: np.ndarray, height: float, yaw: float) -> Pose:
    """The pose at ``xy`` (m), ``height`` (m) and ``yaw`` (rad) in ``frame``, in the world."""
    return frame.compose(Pose.from_xyz_rz(float(xy[0]), float(xy[1]), height, yaw))
