"""``peg``: a chamfered aluminium peg into a hole without walls around it (Johannsmeier et al.
2019).

Johannsmeier et al.'s hardest task: an aluminium peg with a chamfer, into a hole that "has no
walls", so the peg can slide off, tilt and get stuck. The paper's numbers are lost in the extracted
text, so the defaults are plausible ones: a 16 mm peg with a 0.5 mm chamfer, 0.3 mm diametral
clearance, a 25 mm deep hole.

How hard (issue 16, part 4), from the paper's words (Sec. V): a chamfer on the peg only
(``hole_chamfer = 0``: "there is a [x] mm chamfer on the peg"); a free-standing boss whose
rim a 4 mm overhang slides off ("the hole has no walls"); the taught hole error of all three
tasks (0.5 mm per axis: "teaching accuracy below [1] mm"); and ``start_deviation`` 2 mm, the
"deliberate initial pose deviation" of the four starts (as on the puzzle; see
:meth:`~teachfit.tasks.protocols.skill.SkillProtocol.start_frames`). The chamfer's size is
lost; 0.5 mm (1 mm until 2026-12-01) puts the peg's capture range, chamfer plus half the
clearance = 0.65 mm, below the stated teaching accuracy, so that the taught error matters on
the paper's hardest task (P(radial error < 0.65 mm) = 57 % at 0.5 mm per axis; with the 1 mm
chamfer 93 %, and the taught error changed nothing measurable). ``teachfit bench learning
--random-rate N`` measures how often random parameters then succeed (BENCHMARKS.md: 30 %
with 0.5 mm, 51 % with 1 mm).

Geometry. The hole is bored into the top of a thin-walled boss (a tube, outer diameter
``boss_diameter``) standing ``boss_height`` tall on a base plate (top at ``base_height``),
centred on the world origin (:mod:`teachfit.tasks.scene.round_hole`). Nothing surrounds the
boss: a peg pushed more than about the wall thickness off the axis overhangs the rim, tips and
slides off it, and a peg beside the boss goes down to the plate -- deep below the hole entry,
yet not inserted: :meth:`ground_truth_inserted` asks for the TCP on the hole axis, and
:meth:`detect_success` for the TCP within :attr:`detection_radius` (the overhang offset) of
the nominal axis.

Frames. The hole frame (:attr:`hole2world`) is at the centre of the hole entry (the boss top),
z up. The TCP is the centre of the peg's tip face, the peg's axis +z. The search is in x, y.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from teachfit.tasks.geometry.round_peg import RoundPegParams
from teachfit.tasks.geometry.skill import SkillTask
from teachfit.tasks.params import doc_field
from teachfit.tasks.protocols.skill import SkillProtocolParams
from teachfit.tasks.scene.round_hole import BossScene


@dataclass(frozen=True)
class AluminiumPegParams(SkillProtocolParams, RoundPegParams):
    """Parameters of :class:`AluminiumPeg`; every length in metres."""

    task_name: ClassVar[str] = "peg"

    peg_diameter: float = doc_field("peg diameter (m)", 0.016, above=0)
    clearance: float = doc_field(
        "diametral clearance: hole diameter minus peg diameter (m)", 3e-4, above=0
    )
    peg_chamfer: float = doc_field("45-degree chamfer on the peg tip edge (m)", 0.0005, at_least=0)
    peg_length: float = doc_field("length of the peg below the wrist sensor (m)", 0.060, above=0)
    hole_depth: float = doc_field("depth of the hole below the boss top (m)", 0.025, above=0)
    hole_chamfer: float = doc_field("45-degree chamfer on the hole entry edge (m)", 0.0, at_least=0)
    boss_diameter: float = doc_field(
        "outer diameter of the boss holding the hole (m)", 0.024, above=0
    )
    boss_height: float = doc_field("height of the boss above the base plate (m)", 0.040, above=0)
    base_height: float = doc_field("height of the base plate's top (m, world z)", 0.010, above=0)
    base_half_width: float = doc_field("half side of the square base plate (m)", 0.060, above=0)
    success_depth: float = doc_field("insertion depth that counts as success (m)", 0.015, above=0)
    demo_offset: float = doc_field(
        "distance of the blind teacher's start from the hole (m)", 0.003, above=0
    )
    start_deviation: float = doc_field(
        "deliberate deviation of each start's hole estimate from the taught one (m)",
        0.002,
        at_least=0,
    )
    n_sectors: int = doc_field("convex sectors forming the boss wall", 32)

    def check(self) -> None:
        super().check()
        self.require(
            self.clearance < self.peg_diameter / 4,
            f"clearance {self.clearance} must be below a quarter of the peg diameter "
            f"({self.peg_diameter}): that is no tight fit",
        )
        wall = (self.boss_diameter - self.peg_diameter - self.clearance) / 2 - self.hole_chamfer
        self.require(
            wall >= 0.001,
            f"boss_diameter {self.boss_diameter} leaves a wall of {wall:.4f} m around the hole "
            "(chamfer included); need at least 1 mm",
        )
        self.require(
            self.hole_depth + 0.002 <= self.boss_height,
            "hole_depth must be at least 2 mm less than boss_height (the hole bottom)",
        )
        self.require(
            self.base_half_width >= self.boss_diameter / 2 + self.peg_diameter,
            "base_half_width must leave room for the peg beside the boss",
        )
        self.require(
            self.demo_offset + self.peg_diameter / 2 <= self.boss_diameter / 2,
            "demo_offset puts the teacher's start (partly) off the boss top",
        )
        self.check_round_peg()


class AluminiumPeg(SkillTask):
    """Chamfered round peg into a hole in a free-standing boss; search in x, y."""

    name = "peg"
    description = (
        "chamfered aluminium peg into a hole with no walls around it; x-y "
        "(Johannsmeier et al. 2019)"
    )
    search_dims = ("x", "y")
    params_type = AluminiumPegParams
    scene_type = BossScene
    params: AluminiumPegParams

    @property
    def surface_z(self) -> float:
        return self.params.base_height + self.params.boss_height

    @property
    def hole_depth(self) -> float:
        return self.params.hole_depth

    @property
    def overhang_offset(self) -> float:
        """Lateral TCP offset (m) beyond which the peg's tip overhangs the boss rim."""
        return (self.params.boss_diameter - self.params.peg_diameter) / 2

    @property
    def detection_radius(self) -> float:
        """Within :attr:`overhang_offset` the whole peg tip is over the boss top."""
        return self.overhang_offset
