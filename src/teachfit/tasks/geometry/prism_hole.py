"""What the prism-hole cells (``puzzle``, ``key``) share: a polygonal hole in a square block.

The block is a square of half side ``block_half_width`` (top at ``block_height``, world z)
centred on the world origin and turned by ``hole_yaw`` about z; the hole (depth
:attr:`PrismHoleParams.depth_field`) is a convex polygon at its centre
(:mod:`teachfit.tasks.scene.prism_hole`). The hole frame is the hole's entry centre, z up,
turned by ``hole_yaw``. Lengths in metres, angles in radians.
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass
from typing import ClassVar

from teachfit.core.geometry import Pose
from teachfit.tasks.geometry.skill import SkillTask
from teachfit.tasks.params import doc_field
from teachfit.tasks.protocols.skill import SkillProtocolParams


@dataclass(frozen=True)
class PrismHoleParams(SkillProtocolParams):
    """Fields and checks shared by the prism-hole cells (subclasses may change defaults).

    Subclasses add the part, the hole depth (the field named by :attr:`depth_field`) and the
    extents :attr:`hole_reach` and :attr:`part_radius`.
    """

    #: name of the field holding the hole's depth below the block top (m)
    depth_field: ClassVar[str] = "hole_depth"
    #: the hole and the block top, as validation messages name them
    hole_word: ClassVar[str] = "hole"
    face_word: ClassVar[str] = "block"
    #: least rim (m) the block must leave around the hole
    min_rim: ClassVar[float] = 0.005

    clearance: float = doc_field("clearance of the part in the hole (m)", 0.0004, above=0)
    hole_yaw: float = doc_field("yaw of the hole (and block) about world z (rad)", 0.0)
    block_half_width: float = doc_field(
        "half side of the square block holding the hole (m)", 0.045, above=0
    )
    block_height: float = doc_field(
        "height of the block's top surface (m, world z)", 0.040, above=0
    )
    success_depth: float = doc_field("insertion depth that counts as success (m)", 0.010, above=0)
    a_r_max: float = doc_field(
        "largest rotational oscillation amplitude the skill may learn (rad); 0: the part's yaw "
        "play in the hole, clearance / yaw lever",
        0.0,
        at_least=0,
    )

    @property
    @abstractmethod
    def hole_reach(self) -> float:
        """Farthest distance (m) of the hole's entry (chamfer included) from its centre."""

    @property
    @abstractmethod
    def part_radius(self) -> float:
        """Farthest distance (m) of the held part's bottom outline from the TCP axis."""

    def check(self) -> None:
        super().check()
        depth = getattr(self, self.depth_field)
        self.require(
            self.hole_reach + self.min_rim <= self.block_half_width,
            f"block_half_width {self.block_half_width} leaves less than a "
            f"{self.min_rim * 1e3:.0f} mm rim around the {self.hole_word} (it reaches "
            f"{self.hole_reach:.4f} m)",
        )
        self.require(
            depth + 0.002 <= self.block_height,
            f"{self.depth_field} must be at least 2 mm less than block_height "
            f"(the {self.hole_word} bottom)",
        )
        self.require_reachable(self.success_depth, depth, self.hole_word)
        self.require(
            self.demo_offset + self.part_radius <= self.block_half_width,
            f"demo_offset puts the teacher's start (partly) off the {self.face_word}",
        )


class PrismHoleTask(SkillTask):
    """A prism part into a polygonal hole in a turned square block; search x, y and rz."""

    params: PrismHoleParams
    search_dims = ("x", "y", "rz")

    @property
    def surface_z(self) -> float:
        return self.params.block_height

    @property
    def hole2world(self) -> Pose:
        p = self.params
        return Pose.from_xyz_rz(0.0, 0.0, p.block_height, p.hole_yaw)

    @property
    def hole_depth(self) -> float:
        return float(getattr(self.params, self.params.depth_field))

    @property
    @abstractmethod
    def yaw_lever(self) -> float:
        """Length (m) over which the clearance limits the part's yaw in the hole."""

    @property
    def yaw_play(self) -> float:
        """How far a centred part can turn in the hole before it touches a wall (rad),
        ``clearance / yaw_lever``."""
        return self.params.clearance / self.yaw_lever

    @property
    def rz_tolerance(self) -> float:
        """Twice the yaw play of a centred part plus 0.01 rad for soft-contact penetration."""
        return 2 * self.yaw_play + 0.01

    @property
    def skill_domains(self) -> dict[str, tuple[float, float]]:
        """The learned skill parameters this task bounds tighter than the skill's domain:
        the rotational oscillation amplitude ``a_r`` up to ``a_r_max``, by default the
        part's :attr:`yaw_play`.

        Johannsmeier et al. 2019 gives each task its own "maximum rotational amplitude of the
        oscillatory motion" (Sec. V; the values are lost in the extracted text) and derives the
        domains from system and safety limits. For a part that cannot turn freely in its hole the
        limit is the hole: an amplitude beyond the yaw play only twists the part's corners
        into the walls. A round part (``peg``) keeps the skill's 0.1 rad.
        """
        return {"a_r": (0.0, self.params.a_r_max or self.yaw_play)}

    @property
    def detection_radius(self) -> float:
        """Within the block's half side minus the part's radius the part is over the block."""
        return self.params.block_half_width - self.params.part_radius
