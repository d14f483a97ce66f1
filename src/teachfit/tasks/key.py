"""``key``: a flat key blade into a narrow chamfered slot (seed B).

Seed B's second task: a key whose tip and keyhole are chamfered, which makes the first entry
easy; the hole is so small that the paper applied no deliberate start deviation. The paper's
numbers are lost in the extracted text, so the defaults are plausible ones: a 7 mm x 2 mm
blade 30 mm long with 0.5 mm tip chamfers, a slot 0.3 mm wider in both directions, 20 mm deep,
with 0.8 mm entry chamfers, in a 40 mm square lock face.

Geometry. The lock block is a square of half-width ``block_half_width`` (top at
``block_height``, world z) centred on the world origin, turned by ``hole_yaw`` about z. The
slot is a rectangle ``blade_width + clearance`` (along the hole frame's x) by
``blade_thickness + clearance`` (along y), built from four convex pieces, one beyond each slot
edge with a 45-degree chamfer of ``slot_chamfer`` along it, plus a box below its bottom. The
held part is the blade (its tip chamfered by ``blade_chamfer`` on all four edges) under a wider
bow that stays above the lock face.

Frames. The hole frame (:attr:`hole2world`) is the centre of the slot at the lock face (the
top of its chamfers), z up, turned by ``hole_yaw``. The TCP is the centre of the blade's tip
face, the blade's width along its x. The blade is 2-fold symmetric: :attr:`rz_period` is pi.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.tasks.base import ContactParams
from teachfit.tasks.mjcf import SceneXml, contact_attrs, fmt
from teachfit.tasks.prism_geometry import beyond_edge_block, chamfered_prism, rectangle
from teachfit.tasks.skill_protocol import (
    SkillProtocolParams,
    SkillTask,
    doc_field,
)


@dataclass(frozen=True)
class KeyParams(SkillProtocolParams):
    """Parameters of :class:`Key`; every length in metres, angles in radians."""

    task_name: ClassVar[str] = "key"

    blade_width: float = doc_field("width of the key blade, along the hole frame's x (m)", 0.007)
    blade_thickness: float = doc_field("thickness of the blade, along y (m)", 0.002)
    blade_length: float = doc_field("length of the blade below the bow (m)", 0.030)
    blade_chamfer: float = doc_field("45-degree chamfer on the blade tip's edges (m)", 0.0005)
    clearance: float = doc_field("slot size minus blade size, in width and thickness (m)", 0.0003)
    slot_depth: float = doc_field("depth of the slot below the lock face (m)", 0.020)
    slot_chamfer: float = doc_field("45-degree chamfer on the slot's entry edges (m)", 0.0008)
    hole_yaw: float = doc_field("yaw of the slot (and block) about world z (rad)", 0.0)
    bow_width: float = doc_field("width of the key bow above the blade (m)", 0.020)
    bow_thickness: float = doc_field("thickness of the bow (m)", 0.003)
    bow_height: float = doc_field("height of the bow (m)", 0.015)
    block_half_width: float = doc_field("half side of the square lock face (m)", 0.020)
    block_height: float = doc_field("height of the lock face (m, world z)", 0.040)
    success_depth: float = doc_field("insertion depth that counts as success (m)", 0.012)
    start_offset: float = doc_field("lateral offset of the skill starts from the hole (m)", 0.0005)
    hole_pos_sigma: float = doc_field("std of the taught hole position, per axis (m)", 0.0003)
    hole_yaw_sigma: float = doc_field("std of the taught hole yaw (rad)", 0.0087)
    demo_offset: float = doc_field("distance of the blind teacher's start from the hole (m)", 0.008)

    def __post_init__(self) -> None:
        super().__post_init__()
        for key in (
            "blade_width",
            "blade_thickness",
            "blade_length",
            "clearance",
            "slot_depth",
            "bow_width",
            "bow_thickness",
            "bow_height",
            "block_half_width",
            "block_height",
            "success_depth",
        ):
            self.require(getattr(self, key) > 0, f"{key} must be > 0, got {getattr(self, key)}")
        for key in ("blade_chamfer", "slot_chamfer"):
            self.require(getattr(self, key) >= 0, f"{key} must be >= 0, got {getattr(self, key)}")
        self.require(
            self.blade_thickness < self.blade_width,
            "blade_thickness must be smaller than blade_width (a flat blade)",
        )
        self.require(
            self.clearance < self.blade_thickness,
            f"clearance {self.clearance} must be smaller than blade_thickness "
            f"({self.blade_thickness}): that is no tight fit",
        )
        self.require(
            self.blade_chamfer < self.blade_thickness / 2,
            "blade_chamfer must be smaller than half the blade thickness",
        )
        reach = (self.blade_width + self.clearance) / 2 + self.slot_chamfer
        self.require(
            reach + 0.003 <= self.block_half_width,
            f"block_half_width {self.block_half_width} leaves less than a 3 mm rim around the "
            f"slot (it reaches {reach:.4f} m)",
        )
        self.require(
            self.slot_depth + 0.002 <= self.block_height,
            "slot_depth must be at least 2 mm less than block_height (the slot bottom)",
        )
        self.require(
            self.slot_chamfer < self.slot_depth, "slot_chamfer must be smaller than slot_depth"
        )
        self.require(
            self.success_depth <= self.slot_depth,
            f"success_depth {self.success_depth} is deeper than the slot ({self.slot_depth}): "
            "impossible to succeed",
        )
        self.require(
            self.blade_length >= self.slot_depth + 0.001,
            "blade_length must exceed slot_depth by >= 1 mm (the bow stays above the lock face)",
        )
        self.require(
            self.bow_width >= self.blade_width and self.bow_thickness >= self.blade_thickness,
            "the bow must be at least as wide and thick as the blade",
        )
        self.require(
            self.demo_offset + self.blade_width / 2 <= self.block_half_width,
            "demo_offset puts the teacher's start (partly) off the lock face",
        )


class Key(SkillTask):
    """Flat key blade into a narrow chamfered slot; search in x, y and rz."""

    name = "key"
    description = "flat key blade into a narrow chamfered slot; search x-y-rz (seed B)"
    search_dims = ("x", "y", "rz")
    params_type = KeyParams
    params: KeyParams
    #: the blade is 2-fold symmetric: it inserts at rz and rz + pi (rad)
    rz_period: ClassVar[float] = float(np.pi)

    @property
    def surface_z(self) -> float:
        return self.params.block_height

    @property
    def hole2world(self) -> Pose:
        return Pose.from_xyz_rz(0.0, 0.0, self.params.block_height, self.params.hole_yaw)

    @property
    def hole_depth(self) -> float:
        return self.params.slot_depth

    @property
    def rz_tolerance(self) -> float:
        """Twice the yaw play of a centred blade plus 0.01 rad for soft-contact penetration."""
        p = self.params
        return 2 * p.clearance / (p.blade_width + p.blade_thickness) + 0.01

    @property
    def held_part_length(self) -> float:
        return self.params.blade_length + self.params.bow_height

    @property
    def slot_half_size(self) -> tuple[float, float]:
        """Half width (x) and half thickness (y) of the slot below its chamfers (m)."""
        p = self.params
        return (p.blade_width + p.clearance) / 2, (p.blade_thickness + p.clearance) / 2

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        z_bot = p.block_height - p.slot_depth
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
        hx, hy = self.slot_half_size
        outline = rectangle(p.block_half_width, p.block_half_width)
        sides = {
            "east": ((1.0, 0.0), hx),
            "west": ((-1.0, 0.0), hx),
            "north": ((0.0, 1.0), hy),
            "south": ((0.0, -1.0), hy),
        }
        for side, (normal, offset) in sides.items():
            verts = beyond_edge_block(
                outline, np.array(normal), offset, z_bot, p.block_height, p.slot_chamfer
            )
            scene.add_mesh(f"slot_{side}", verts)
            ET.SubElement(
                block,
                "geom",
                name=f"slot_wall_{side}",
                type="mesh",
                mesh=f"slot_{side}",
                material="metal",
                **kw,
            )

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        kw = contact_attrs(contact)
        blade = rectangle(p.blade_width / 2, p.blade_thickness / 2)
        scene.add_mesh("key_blade", chamfered_prism(blade, p.blade_length, p.blade_chamfer))
        ET.SubElement(
            body,
            "geom",
            name="key_blade",
            type="mesh",
            mesh="key_blade",
            material="tool",
            mass="0.005",
            **kw,
        )
        ET.SubElement(
            body,
            "geom",
            name="key_bow",
            type="box",
            size=fmt([p.bow_width / 2, p.bow_thickness / 2, p.bow_height / 2]),
            pos=fmt([0, 0, p.blade_length + p.bow_height / 2]),
            material="tool",
            mass="0.01",
            **kw,
        )
