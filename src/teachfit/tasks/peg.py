"""``peg``: a chamfered aluminium peg into a hole without walls around it (seed B).

Seed B's hardest task: an aluminium peg with a chamfer, into a hole that "has no walls", so the
peg can slide off, tilt and get stuck. The paper's numbers are lost in the extracted text, so
the defaults are plausible ones: a 16 mm peg with a 1 mm chamfer, 0.3 mm diametral clearance,
a 25 mm deep hole.

Geometry. The hole is bored into the top of a thin-walled boss (a tube, outer diameter
``boss_diameter``) standing ``boss_height`` tall on a base plate (top at ``base_height``),
centred on the world origin. Nothing surrounds the boss: a peg pushed more than about the wall
thickness off the axis overhangs the rim, tips and slides off it, and a peg beside the boss
goes down to the plate (deep below the hole entry, yet not inserted:
:meth:`ground_truth_inserted` also
asks for the TCP on the hole axis). The boss wall is ``n_sectors`` convex ring sectors whose
polygonal hole circumscribes the nominal circle; a solid cylinder fills it below the hole.

Frames. The hole frame (:attr:`hole2world`) is at the centre of the hole entry (the boss top),
z up. The TCP is the centre of the peg's tip face, the peg's axis +z. The search is in x, y.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.tasks.base import ContactParams
from teachfit.tasks.mjcf import SceneXml, chamfered_cylinder, contact_attrs, fmt, ring_sector
from teachfit.tasks.skill_protocol import (
    SkillProtocolParams,
    SkillTask,
    doc_field,
)

ALUMINIUM_DENSITY = 2700.0  # kg/m^3


@dataclass(frozen=True)
class AluminiumPegParams(SkillProtocolParams):
    """Parameters of :class:`AluminiumPeg`; every length in metres."""

    task_name: ClassVar[str] = "peg"

    peg_diameter: float = doc_field("peg diameter (m)", 0.016)
    clearance: float = doc_field("diametral clearance: hole diameter minus peg diameter (m)", 3e-4)
    peg_chamfer: float = doc_field("45-degree chamfer on the peg tip edge (m)", 0.001)
    peg_length: float = doc_field("length of the peg below the wrist sensor (m)", 0.060)
    hole_depth: float = doc_field("depth of the hole below the boss top (m)", 0.025)
    hole_chamfer: float = doc_field("45-degree chamfer on the hole entry edge (m)", 0.0)
    boss_diameter: float = doc_field("outer diameter of the boss holding the hole (m)", 0.024)
    boss_height: float = doc_field("height of the boss above the base plate (m)", 0.040)
    base_height: float = doc_field("height of the base plate's top (m, world z)", 0.010)
    base_half_width: float = doc_field("half side of the square base plate (m)", 0.060)
    success_depth: float = doc_field("insertion depth that counts as success (m)", 0.015)
    demo_offset: float = doc_field("distance of the blind teacher's start from the hole (m)", 0.003)
    n_sectors: int = doc_field("convex sectors forming the boss wall", 32)

    def __post_init__(self) -> None:
        super().__post_init__()
        for key in (
            "peg_diameter",
            "clearance",
            "peg_length",
            "hole_depth",
            "boss_diameter",
            "boss_height",
            "base_height",
            "base_half_width",
            "success_depth",
        ):
            self.require(getattr(self, key) > 0, f"{key} must be > 0, got {getattr(self, key)}")
        for key in ("peg_chamfer", "hole_chamfer"):
            self.require(getattr(self, key) >= 0, f"{key} must be >= 0, got {getattr(self, key)}")
        self.require(
            self.clearance < self.peg_diameter / 4,
            f"clearance {self.clearance} must be below a quarter of the peg diameter "
            f"({self.peg_diameter}): that is no tight fit",
        )
        self.require(
            self.peg_chamfer < self.peg_diameter / 2,
            "peg_chamfer must be smaller than the peg radius",
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
            self.success_depth <= self.hole_depth,
            f"success_depth {self.success_depth} is deeper than the hole ({self.hole_depth}): "
            "impossible to succeed",
        )
        self.require(self.peg_length > self.hole_depth, "peg_length must exceed hole_depth")
        self.require(
            self.base_half_width >= self.boss_diameter / 2 + self.peg_diameter,
            "base_half_width must leave room for the peg beside the boss",
        )
        self.require(
            self.demo_offset + self.peg_diameter / 2 <= self.boss_diameter / 2,
            "demo_offset puts the teacher's start (partly) off the boss top",
        )
        self.require(8 <= self.n_sectors <= 256, "n_sectors must be within [8, 256]")


class AluminiumPeg(SkillTask):
    """Chamfered round peg into a hole in a free-standing boss; search in x, y."""

    name = "peg"
    description = "chamfered aluminium peg into a hole with no walls around it; x-y (seed B)"
    search_dims = ("x", "y")
    params_type = AluminiumPegParams
    params: AluminiumPegParams

    @property
    def surface_z(self) -> float:
        return self.params.base_height + self.params.boss_height

    @property
    def hole2world(self) -> Pose:
        return Pose(np.array([0.0, 0.0, self.surface_z]))

    @property
    def hole_depth(self) -> float:
        return self.params.hole_depth

    @property
    def held_part_length(self) -> float:
        return self.params.peg_length

    @property
    def overhang_offset(self) -> float:
        """Lateral TCP offset (m) beyond which the peg's tip overhangs the boss rim."""
        return (self.params.boss_diameter - self.params.peg_diameter) / 2

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        hole_r = (p.peg_diameter + p.clearance) / 2
        boss_r = p.boss_diameter / 2
        top = self.surface_z
        z_hole = top - p.hole_depth
        kw = contact_attrs(contact)
        fixture = ET.SubElement(scene.worldbody, "body", name="fixture")
        ET.SubElement(
            fixture,
            "geom",
            name="fixture_base",
            type="box",
            size=fmt([p.base_half_width, p.base_half_width, p.base_height / 2]),
            pos=fmt([0, 0, p.base_height / 2]),
            material="metal",
            **kw,
        )
        core_half = (z_hole - p.base_height) / 2
        ET.SubElement(
            fixture,
            "geom",
            name="boss_core",
            type="cylinder",
            size=fmt([boss_r, core_half]),
            pos=fmt([0, 0, p.base_height + core_half]),
            material="metal",
            **kw,
        )
        scene.add_mesh(
            "boss_sector", ring_sector(hole_r, boss_r, z_hole, top, p.n_sectors, p.hole_chamfer)
        )
        for i in range(p.n_sectors):
            ET.SubElement(
                fixture,
                "geom",
                name=f"hole_wall_{i}",
                type="mesh",
                mesh="boss_sector",
                euler=fmt([0, 0, 2 * np.pi * i / p.n_sectors]),
                material="metal",
                **kw,
            )

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        r = p.peg_diameter / 2
        scene.add_mesh("alu_peg", chamfered_cylinder(r, p.peg_length, p.peg_chamfer, 48))
        mass = ALUMINIUM_DENSITY * np.pi * r**2 * p.peg_length
        ET.SubElement(
            body,
            "geom",
            name="peg",
            type="mesh",
            mesh="alu_peg",
            material="tool",
            mass=fmt(mass),
            **contact_attrs(contact),
        )
