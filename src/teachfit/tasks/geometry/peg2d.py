"""``peg2d``: a round peg searching on the flat top of a cylinder with a round hole (seed A, 2D).

The fixture is a cylinder of diameter ``block_diameter`` whose top holds a round hole of
diameter ``peg_diameter + clearance`` (diametral clearance) and depth ``hole_depth``, centred at
the world origin. The hole wall is built from ``n_sectors`` convex ring sectors (MuJoCo collides
meshes as convex hulls, :mod:`teachfit.tasks.scene.round_hole`); the polygonal hole
circumscribes the nominal circle so it is never narrower than asked. Orientation is held fixed:
the search is in x-y.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from teachfit.tasks.base import Task
from teachfit.tasks.geometry.round_peg import RoundPegParams
from teachfit.tasks.params import doc_field
from teachfit.tasks.protocols.seed_a import Peg2DProtocol
from teachfit.tasks.scene.round_hole import Peg2DScene


@dataclass(frozen=True)
class Peg2DParams(RoundPegParams):
    """Parameters of :class:`Peg2D`; every length in metres."""

    task_name: ClassVar[str] = "peg2d"

    peg_diameter: float = doc_field("peg diameter (m)", 0.020, above=0)
    clearance: float = doc_field(
        "diametral clearance: hole diameter minus peg diameter (m)", 5e-4, above=0
    )
    hole_depth: float = doc_field("depth of the hole below the top surface (m)", 0.020, above=0)
    peg_length: float = doc_field("length of the peg below the wrist sensor (m)", 0.060, above=0)
    peg_chamfer: float = doc_field("45-degree chamfer on the peg tip edge (m)", 0.001, at_least=0)
    hole_chamfer: float = doc_field(
        "45-degree chamfer on the hole entry edge (m)", 0.0005, at_least=0
    )
    block_diameter: float = doc_field(
        "diameter of the cylinder holding the hole (m)", 0.120, above=0
    )
    block_height: float = doc_field("height of that cylinder's top surface (m)", 0.060, above=0)
    success_depth: float = doc_field("insertion depth that counts as success (m)", 0.010, above=0)
    demo_offset: float = doc_field(
        "distance of the blind teacher's worst-case start (m)", 0.030, above=0
    )
    friction: float = doc_field("sliding friction coefficient peg/block", 0.3, at_least=0)
    n_sectors: int = doc_field("convex sectors forming the hole wall", 32)

    def check(self) -> None:
        self.require(
            self.clearance < self.peg_diameter, "clearance must be smaller than the peg diameter"
        )
        hole_r = (self.peg_diameter + self.clearance) / 2 + self.hole_chamfer
        self.require(
            self.block_diameter / 2 > hole_r + 0.005,
            f"block_diameter {self.block_diameter} leaves no rim around a hole of "
            f"radius {hole_r:.4f} m (need at least 5 mm)",
        )
        self.require(
            self.hole_depth < self.block_height, "hole_depth must be smaller than block_height"
        )
        self.require(
            self.demo_offset + self.peg_diameter / 2 < self.block_diameter / 2,
            "demo_offset puts the teacher's start off the block",
        )
        self.check_round_peg()


class Peg2D(Task):
    """Round peg into a round hole on top of a cylinder; search in x-y, orientation fixed."""

    name = "peg2d"
    description = (
        "round peg into a round hole on a cylinder top; search x-y "
        "(Ehlers et al. 2019, Tables I-II)"
    )
    search_dims = ("x", "y")
    params_type = Peg2DParams
    scene_type = Peg2DScene
    protocol_type = Peg2DProtocol
    params: Peg2DParams

    @property
    def surface_z(self) -> float:
        return self.params.block_height

    @property
    def detection_radius(self) -> float:
        """The peg's footprint stays on the cylinder top within its radius minus the peg's."""
        return (self.params.block_diameter - self.params.peg_diameter) / 2
