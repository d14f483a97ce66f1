"""``puzzle``: an equilateral-triangle puzzle piece into a triangular hole (seed B).

Seed B's first task: a triangular puzzle piece, no chamfers, sub-millimetre tolerance. The
extracted paper text lost its numbers, so the defaults are plausible ones, not the paper's: a
30 mm piece (side), 0.4 mm clearance, a 15 mm deep hole in a 90 mm square block.

Geometry. The block is a square of half-width ``block_half_width`` (top at ``block_height``,
world z) centred on the world origin and turned by ``hole_yaw`` about z. Its hole is an
equilateral triangle whose inscribed circle is ``clearance`` wider (in diameter) than the
piece's, so each edge of a centred, aligned piece has a gap of ``clearance / 2``. The hole is
built from three convex pieces, one beyond each hole edge (:mod:`~teachfit.tasks.prism_geometry`),
plus a box below its bottom.

Frames. The hole frame (:attr:`hole2world`) is at the centre of the hole's entry, z up, turned
by ``hole_yaw``; in it the hole (and, at yaw 0, the piece) has a vertex on +x. The TCP is the
centroid of the piece's bottom face, the piece's axis +z. The piece is 3-fold symmetric:
:attr:`rz_period` is 2 pi / 3. A centred piece can turn by about ``clearance / side_length``
rad before an edge touches, and shift by ``clearance`` towards a vertex.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.tasks.base import ContactParams
from teachfit.tasks.mjcf import SceneXml, contact_attrs, fmt
from teachfit.tasks.prism_geometry import (
    beyond_edge_block,
    chamfered_prism,
    edge_normals,
    rectangle,
    regular_polygon,
)
from teachfit.tasks.skill_protocol import (
    SkillProtocolParams,
    SkillTask,
    doc_field,
)

_PHASE = np.pi / 3  # edge normals at 60, 180, 300 degrees: a vertex on +x


@dataclass(frozen=True)
class PuzzleParams(SkillProtocolParams):
    """Parameters of :class:`Puzzle`; every length in metres, angles in radians."""

    task_name: ClassVar[str] = "puzzle"

    side_length: float = doc_field("side of the triangular piece (m)", 0.030)
    clearance: float = doc_field(
        "hole's inscribed diameter minus the piece's (m); each edge gap is half", 0.0004
    )
    hole_depth: float = doc_field("depth of the hole below the block top (m)", 0.015)
    hole_chamfer: float = doc_field("45-degree chamfer on the hole edges (m); 0 in the paper", 0.0)
    hole_yaw: float = doc_field("yaw of the hole (and block) about world z (rad)", 0.0)
    piece_height: float = doc_field("height of the piece below the wrist sensor (m)", 0.035)
    block_half_width: float = doc_field("half side of the square block holding the hole (m)", 0.045)
    block_height: float = doc_field("height of the block's top surface (m, world z)", 0.040)
    success_depth: float = doc_field("insertion depth that counts as success (m)", 0.010)
    start_yaw: float = doc_field("skill starts draw yaw within +-start_yaw of the hole (rad)", 0.05)
    hole_yaw_sigma: float = doc_field("std of the taught hole yaw (rad)", 0.0175)

    def __post_init__(self) -> None:
        super().__post_init__()
        for key in (
            "side_length",
            "clearance",
            "hole_depth",
            "piece_height",
            "block_half_width",
            "block_height",
            "success_depth",
        ):
            self.require(getattr(self, key) > 0, f"{key} must be > 0, got {getattr(self, key)}")
        self.require(self.hole_chamfer >= 0, f"hole_chamfer must be >= 0, got {self.hole_chamfer}")
        self.require(
            self.clearance < self.side_length / 4,
            f"clearance {self.clearance} must be below a quarter of side_length "
            f"({self.side_length}): that is no tight fit",
        )
        reach = 2 * (self.hole_inradius + self.hole_chamfer)  # hole vertex distance, chamfer incl.
        self.require(
            reach + 0.005 <= self.block_half_width,
            f"block_half_width {self.block_half_width} leaves less than a 5 mm rim around the "
            f"hole (its corners reach {reach:.4f} m)",
        )
        self.require(
            self.hole_depth + 0.002 <= self.block_height,
            "hole_depth must be at least 2 mm less than block_height (the hole bottom)",
        )
        self.require(
            self.success_depth <= self.hole_depth,
            f"success_depth {self.success_depth} is deeper than the hole ({self.hole_depth}): "
            "impossible to succeed",
        )
        self.require(self.piece_height > self.hole_depth, "piece_height must exceed hole_depth")
        self.require(
            self.demo_offset + 2 * self.piece_inradius <= self.block_half_width,
            "demo_offset puts the teacher's start (partly) off the block",
        )

    @property
    def piece_inradius(self) -> float:
        """Distance from the piece's centre to its edges (m)."""
        return self.side_length / (2 * np.sqrt(3.0))

    @property
    def hole_inradius(self) -> float:
        """Distance from the hole's centre to its edges (m)."""
        return self.piece_inradius + self.clearance / 2


class Puzzle(SkillTask):
    """Triangular puzzle piece into a triangular hole, no chamfer; search in x, y and rz."""

    name = "puzzle"
    description = "triangular puzzle piece into a triangular hole, no chamfer; x-y-rz (seed B)"
    search_dims = ("x", "y", "rz")
    params_type = PuzzleParams
    params: PuzzleParams
    #: the triangle is 3-fold symmetric: it inserts at rz, rz + 2 pi / 3, rz + 4 pi / 3 (rad)
    rz_period: ClassVar[float] = float(2 * np.pi / 3)

    @property
    def surface_z(self) -> float:
        return self.params.block_height

    @property
    def hole2world(self) -> Pose:
        return Pose.from_xyz_rz(0.0, 0.0, self.params.block_height, self.params.hole_yaw)

    @property
    def hole_depth(self) -> float:
        return self.params.hole_depth

    @property
    def rz_tolerance(self) -> float:
        """Twice the yaw play of a centred piece plus 0.01 rad for soft-contact penetration."""
        return 2 * self.params.clearance / self.params.side_length + 0.01

    @property
    def held_part_length(self) -> float:
        return self.params.piece_height

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        z_bot = p.block_height - p.hole_depth
        kw = contact_attrs(contact)
        block = ET.SubElement(
            scene.worldbody, "body", name="fixture", euler=fmt([0.0, 0.0, p.hole_yaw])
        )
        ET.SubElement(
            block,
            "geom",
            name="fixture_base",
            type="box",
            size=fmt([p.block_half_width, p.block_half_width, z_bot / 2]),
            pos=fmt([0, 0, z_bot / 2]),
            material="metal",
            **kw,
        )
        outline = rectangle(p.block_half_width, p.block_half_width)
        for i, n in enumerate(edge_normals(3, _PHASE)):
            verts = beyond_edge_block(
                outline, n, p.hole_inradius, z_bot, p.block_height, p.hole_chamfer
            )
            scene.add_mesh(f"puzzle_wall_{i}", verts)
            ET.SubElement(
                block,
                "geom",
                name=f"hole_wall_{i}",
                type="mesh",
                mesh=f"puzzle_wall_{i}",
                material="metal",
                **kw,
            )

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        tri = regular_polygon(3, p.piece_inradius, _PHASE)
        scene.add_mesh("puzzle_piece", chamfered_prism(tri, p.piece_height))
        ET.SubElement(
            body,
            "geom",
            name="puzzle_piece",
            type="mesh",
            mesh="puzzle_piece",
            material="tool",
            mass="0.05",
            **contact_attrs(contact),
        )
