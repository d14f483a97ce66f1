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

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.tasks.base import Task
from teachfit.tasks.params import TaskParams, doc_field
from teachfit.tasks.protocols.seed_a import Peg2DProtocol
from teachfit.tasks.scene.round_hole import Peg2DScene


@dataclass(frozen=True)
class Peg2DParams(TaskParams):
    """Parameters of :class:`Peg2D`; every length in metres."""

    task_name: ClassVar[str] = "peg2d"
    positive: ClassVar[tuple[str, ...]] = (
        "peg_diameter",
        "clearance",
        "hole_depth",
        "peg_length",
        "block_diameter",
        "block_height",
        "success_depth",
        "demo_offset",
    )
    nonnegative: ClassVar[tuple[str, ...]] = ("peg_chamfer", "hole_chamfer", "friction")

    peg_diameter: float = doc_field("peg diameter (m)", 0.020)
    clearance: float = doc_field("diametral clearance: hole diameter minus peg diameter (m)", 5e-4)
    hole_depth: float = doc_field("depth of the hole below the top surface (m)", 0.020)
    peg_length: float = doc_field("length of the peg below the wrist sensor (m)", 0.060)
    peg_chamfer: float = doc_field("45-degree chamfer on the peg tip edge (m)", 0.001)
    hole_chamfer: float = doc_field("45-degree chamfer on the hole entry edge (m)", 0.0005)
    block_diameter: float = doc_field("diameter of the cylinder holding the hole (m)", 0.120)
    block_height: float = doc_field("height of that cylinder's top surface (m)", 0.060)
    success_depth: float = doc_field("insertion depth that counts as success (m)", 0.010)
    demo_offset: float = doc_field("distance of the blind teacher's worst-case start (m)", 0.030)
    friction: float = doc_field("sliding friction coefficient peg/block", 0.3)
    n_sectors: int = doc_field("convex sectors forming the hole wall", 32)

    def check(self) -> None:
        self.require(
            self.clearance < self.peg_diameter, "clearance must be smaller than the peg diameter"
        )
        self.require(
            self.peg_chamfer < self.peg_diameter / 2,
            "peg_chamfer must be smaller than the peg radius",
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
        self.require_reachable(self.success_depth, self.hole_depth, "hole")
        self.require(self.peg_length > self.hole_depth, "peg_length must exceed hole_depth")
        self.require(
            self.demo_offset + self.peg_diameter / 2 < self.block_diameter / 2,
            "demo_offset puts the teacher's start off the block",
        )
        self.require(8 <= self.n_sectors <= 256, "n_sectors must be within [8, 256]")


class Peg2D(Task):
    """Round peg into a round hole on top of a cylinder; search in x-y, orientation fixed."""

    name = "peg2d"
    description = "round peg into a round hole on a cylinder top; search x-y (seed A, 2D)"
    search_dims = ("x", "y")
    params_type = Peg2DParams
    scene_type = Peg2DScene
    protocol_type = Peg2DProtocol
    params: Peg2DParams

    @property
    def surface_z(self) -> float:
        return self.params.block_height

    @property
    def hole2world(self) -> Pose:
        return Pose(np.array([0.0, 0.0, self.surface_z]))

    @property
    def detection_radius(self) -> float:
        """The peg's footprint stays on the cylinder top within its radius minus the peg's."""
        return (self.params.block_diameter - self.params.peg_diameter) / 2
