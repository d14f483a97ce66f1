"""Scenes of the round-hole cells: ``peg2d`` (a hole in a cylinder) and ``peg`` (a boss).

Both bore a round hole of radius ``(peg_diameter + clearance) / 2`` into a ring of
``n_sectors`` convex sectors (the polygonal hole circumscribes the nominal circle, so it is
never narrower than asked, :func:`~teachfit.tasks.scene.mjcf.ring_sector`) above a solid
bottom, and hold a chamfered round peg whose tip centre is the TCP. World frame z up, the hole
axis on world z, lengths in metres.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING

import numpy as np

from teachfit.tasks.scene.builder import (
    SceneBuilder,
    add_geom,
    add_mesh_geom,
    add_ring,
    fixture_body,
)
from teachfit.tasks.scene.mjcf import ContactParams, SceneXml, chamfered_cylinder, ring_sector

if TYPE_CHECKING:
    from teachfit.tasks.geometry.peg import AluminiumPeg
    from teachfit.tasks.geometry.peg2d import Peg2D

ALUMINIUM_DENSITY = 2700.0  # kg/m^3


class RoundPegScene(SceneBuilder):
    """A round peg (``peg_diameter``, ``peg_length``, ``peg_chamfer``) in a round hole."""

    task: Peg2D | AluminiumPeg

    @property
    def held_part_length(self) -> float:
        return self.task.params.peg_length

    @property
    def peg_mass(self) -> float:
        """Mass of the peg (kg)."""
        return 0.1

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        p = self.task.params
        peg = chamfered_cylinder(p.peg_diameter / 2, p.peg_length, p.peg_chamfer, 48)
        add_mesh_geom(body, scene, "peg", peg, contact, "tool", mass=self.peg_mass)

    def add_hole_wall(
        self, block: ET.Element, scene: SceneXml, outer_r: float, contact: ContactParams
    ) -> None:
        """The ring around the hole, from ``hole_depth`` below the entry up to it."""
        p = self.task.params
        top = self.task.surface_z
        hole_r = (p.peg_diameter + p.clearance) / 2
        sector = ring_sector(hole_r, outer_r, top - p.hole_depth, top, p.n_sectors, p.hole_chamfer)
        add_ring(block, scene, "hole_sector", sector, p.n_sectors, "hole_wall_", contact)


class Peg2DScene(RoundPegScene):
    """``peg2d``: a cylinder of ``block_diameter`` holding the hole in its top."""

    task: Peg2D

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        p = self.task.params
        outer_r = p.block_diameter / 2
        z_bot = p.block_height - p.hole_depth
        block = fixture_body(scene)
        add_geom(
            block,
            "fixture_base",
            contact,
            type="cylinder",
            size=[outer_r, z_bot / 2],
            pos=[0, 0, z_bot / 2],
        )
        self.add_hole_wall(block, scene, outer_r, contact)


class BossScene(RoundPegScene):
    """``peg``: a thin-walled boss on a square base plate, nothing around it; aluminium peg."""

    task: AluminiumPeg

    @property
    def peg_mass(self) -> float:
        p = self.task.params
        return ALUMINIUM_DENSITY * np.pi * (p.peg_diameter / 2) ** 2 * p.peg_length

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        p = self.task.params
        boss_r = p.boss_diameter / 2
        z_hole = self.task.surface_z - p.hole_depth
        fixture = fixture_body(scene)
        plate = [p.base_half_width, p.base_half_width, p.base_height / 2]
        add_geom(fixture, "fixture_base", contact, type="box", size=plate, pos=[0, 0, plate[2]])
        core_half = (z_hole - p.base_height) / 2
        add_geom(
            fixture,
            "boss_core",
            contact,
            type="cylinder",
            size=[boss_r, core_half],
            pos=[0, 0, p.base_height + core_half],
        )
        self.add_hole_wall(fixture, scene, boss_r, contact)
