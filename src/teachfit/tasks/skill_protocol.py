"""What the skill-learning paper's tasks share: its start protocol and the taught hole pose.

Seed B (Johannsmeier et al., ICRA 2019) evaluates every trial from *four slightly different
start poses* above the hole, and the skill only knows the hole pose a human taught it (with an
error below a millimetre). :class:`SkillTask` provides both for ``puzzle``, ``key`` and ``peg``:

* :meth:`SkillTask.skill_starts` / ``protocol_starts("skill", n, rng)``: ``n`` (4 in the paper)
  TCP poses ``approach_height`` above the surface, ``start_offset`` from the hole axis in evenly
  spread directions (a random common phase) and yaw within ``+-start_yaw`` of the hole's,
  deterministic for a generator state.
* :meth:`SkillTask.estimated_hole`: the hole frame with Gaussian errors in x, y (``hole_pos_sigma``)
  and yaw (``hole_yaw_sigma``), the skill's context parameter.

Frames as in :mod:`teachfit.tasks.base`: world z up, the hole frame at the entry centre.
"""

from __future__ import annotations

import dataclasses
from abc import abstractmethod
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.tasks.base import Task


def doc_field(text: str, default: float | int) -> Any:
    """A dataclass field with a default and a description for ``teachfit tasks``."""
    return field(default=default, metadata={"doc": text})


@dataclass(frozen=True)
class SkillProtocolParams:
    """Start protocol, taught-hole error and friction shared by the skill paper's tasks.

    Lengths in metres, angles in radians. Subclasses add the geometry and may change defaults.
    """

    task_name: ClassVar[str] = "task"

    approach_height: float = doc_field("height of the skill starts above the surface (m)", 0.025)
    start_offset: float = doc_field("lateral offset of the skill starts from the hole (m)", 0.002)
    start_yaw: float = doc_field("skill starts draw yaw within +-start_yaw of the hole (rad)", 0.0)
    hole_pos_sigma: float = doc_field("std of the taught hole position, per axis (m)", 0.0005)
    hole_yaw_sigma: float = doc_field("std of the taught hole yaw (rad)", 0.0)
    demo_offset: float = doc_field("distance of the blind teacher's start from the hole (m)", 0.02)
    friction: float = doc_field("sliding friction coefficient part/fixture", 0.3)

    def __post_init__(self) -> None:
        name = self.task_name
        for key in ("approach_height", "demo_offset"):
            if not getattr(self, key) > 0:
                raise TaskError(f"{name}: {key} must be > 0, got {getattr(self, key)}")
        for key in ("start_offset", "start_yaw", "hole_pos_sigma", "hole_yaw_sigma", "friction"):
            if not getattr(self, key) >= 0:
                raise TaskError(f"{name}: {key} must be >= 0, got {getattr(self, key)}")
        if self.start_yaw >= np.pi / 4:
            raise TaskError(f"{name}: start_yaw must be below pi/4, got {self.start_yaw}")

    def require(self, condition: bool, message: str) -> None:
        """Raise :class:`TaskError` with ``message`` (prefixed by the task name) unless true."""
        if not condition:
            raise TaskError(f"{self.task_name}: {message}")


_SHARED = {f.name for f in dataclasses.fields(SkillProtocolParams)}


class SkillTask(Task):
    """A :class:`Task` with seed B's protocols; ``params`` derive from :class:`SkillProtocolParams`.

    Subclasses with ``"rz"`` in ``search_dims`` set ``rz_period`` (the part's rotational
    symmetry, rad) and :attr:`rz_tolerance`.
    """

    params: SkillProtocolParams

    @property
    def success_depth(self) -> float:
        return float(self.params.success_depth)  # type: ignore[attr-defined]

    @property
    def capture_radius(self) -> float:
        """The part's clearance plus 0.1 mm of soft-contact give (m)."""
        return float(self.params.clearance) + 1e-4  # type: ignore[attr-defined]

    @property
    @abstractmethod
    def hole_depth(self) -> float:
        """Depth of the hole below its entry (m): a context parameter of the skill."""

    @property
    def has_rz(self) -> bool:
        return "rz" in self.search_dims

    @property
    def rz_tolerance(self) -> float:
        """Largest yaw error (rad, modulo ``rz_period``) an inserted part can have."""
        return float(np.pi)

    # ------------------------------------------------------------------------- ground truth
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

    # ---------------------------------------------------------------------------- protocols
    def search_pose(self, state: np.ndarray, search2world: Pose, height: float = 0.0) -> Pose:
        s = np.asarray(state, dtype=float)
        dims = self.search_dims
        if s.shape != (len(dims),):
            raise TaskError(f"{self.name} search states are ({', '.join(dims)}), got {s.shape}")
        rz = float(s[2]) if self.has_rz else 0.0
        return search2world.compose(Pose.from_xyz_rz(s[0], s[1], height, rz))

    def teacher_start(self, rng: np.random.Generator) -> Pose:
        """On the surface ``demo_offset`` from the hole in a random direction (hole frame).

        Tasks searching rz also draw a yaw within ``+-start_yaw`` of the hole's.
        """
        ang = rng.uniform(0.0, 2 * np.pi)
        yaw = rng.uniform(-self.params.start_yaw, self.params.start_yaw) if self.has_rz else 0.0
        off = self.params.demo_offset * np.array([np.cos(ang), np.sin(ang)])
        return self._in_hole_frame(off, self.surface_z - self.hole2world.pos[2], yaw)

    def skill_starts(self, rng: np.random.Generator, around: Pose | None = None) -> list[Pose]:
        """The paper's four slightly different start poses of one trial.

        ``around`` is the frame they are spread around (e.g. :meth:`estimated_hole`); by
        default the true hole frame. See :meth:`protocol_starts` (``"skill"``).
        """
        return self._skill_starts(4, rng, around)

    def protocol_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None = None
    ) -> list[Pose]:
        """Starts for seed B's protocol.

        ``"skill"``: ``n`` TCP poses ``approach_height`` above the surface, ``start_offset`` from
        the hole axis in directions ``2 pi k / n`` plus one random phase, yaw (relative to the
        hole) uniform within ``+-start_yaw``; the paper uses ``n = 4``. ``"teacher"``: the blind
        teacher's starts on the surface. ``demo_start`` is not used.
        """
        del demo_start
        if n <= 0:
            raise TaskError(f"number of starts must be positive, got {n}")
        if protocol == "teacher":
            return [self.teacher_start(rng) for _ in range(n)]
        if protocol != "skill":
            raise TaskError(f"{self.name} has protocols skill, teacher; not {protocol!r}")
        return self._skill_starts(n, rng, None)

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
        ps = self.params.hole_pos_sigma if pos_sigma is None else pos_sigma
        ys = self.params.hole_yaw_sigma if yaw_sigma is None else yaw_sigma
        if ps < 0 or ys < 0:
            raise TaskError(f"estimated_hole sigmas must be >= 0, got {ps}, {ys}")
        dx, dy = rng.normal(0.0, ps, 2) if ps > 0 else (0.0, 0.0)
        dyaw = float(rng.normal(0.0, ys)) if ys > 0 else 0.0
        return self.hole2world.compose(Pose.from_xyz_rz(dx, dy, 0.0, dyaw))

    def param_table(self) -> list[tuple[str, Any, str]]:
        """Parameter rows, the task's own geometry first, the shared protocol ones after."""
        rows = super().param_table()
        return [r for r in rows if r[0] not in _SHARED] + [r for r in rows if r[0] in _SHARED]

    # ------------------------------------------------------------------------------ helpers
    def _in_hole_frame(
        self, xy: np.ndarray, height: float, yaw: float, frame: Pose | None = None
    ) -> Pose:
        frame = self.hole2world if frame is None else frame
        return frame.compose(Pose.from_xyz_rz(float(xy[0]), float(xy[1]), height, yaw))

    def _skill_starts(self, n: int, rng: np.random.Generator, around: Pose | None) -> list[Pose]:
        p = self.params
        phase = rng.uniform(0.0, 2 * np.pi)
        ang = phase + 2 * np.pi * np.arange(n) / n
        yaw = rng.uniform(-p.start_yaw, p.start_yaw, n) if self.has_rz else np.zeros(n)
        frame = self.hole2world if around is None else around
        height = self.surface_z - frame.pos[2] + p.approach_height
        return [
            self._in_hole_frame(
                p.start_offset * np.array([np.cos(a), np.sin(a)]), height, float(y), frame
            )
            for a, y in zip(ang, yaw, strict=True)
        ]
