"""Scenes of the prism-hole cells: ``puzzle`` (a triangle) and ``key`` (a warded slot).

Both cut a convex polygonal hole into a square block (half side ``block_half_width``, top at
``block_height``, world z) turned by ``hole_yaw`` about world z. The hole is built from one
convex piece per hole edge, the part of the block beyond that edge's line
(:func:`~teachfit.tasks.scene.prisms.beyond_edge_block`, optionally chamfered), plus a box
below the hole's bottom, and any convex pieces standing in the hole (:meth:`PrismHoleScene.
hole_wards`: the key's wards, :func:`~teachfit.tasks.scene.prisms.chamfered_block`). The held
part is a prism (the key: two) whose bottom-face centre is the TCP. Lengths
in metres, angles in radians, the fixture's body frame is the hole frame at the block's foot.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from abc import abstractmethod
from typing import TYPE_CHECKING

import numpy as np

from teachfit.tasks.scene.builder import SceneBuilder, add_geom, add_mesh_geom, fixture_body
from teachfit.tasks.scene.mjcf import ContactParams, SceneXml
from teachfit.tasks.scene.prisms import (
    beyond_edge_block,
    chamfered_block,
    chamfered_prism,
    edge_normals,
    rectangle,
    regular_polygon,
)

if TYPE_CHECKING:
    from teachfit.tasks.geometry.key import Key
    from teachfit.tasks.geometry.prism_hole import PrismHoleTask
    from teachfit.tasks.geometry.puzzle import Puzzle

#: edge normals of the puzzle's triangle at 60, 180, 300 degrees: a vertex on +x
TRIANGLE_PHASE = np.pi / 3


class PrismHoleScene(SceneBuilder):
    """A block with a convex polygonal hole of :meth:`hole_edges`; subclasses add the part."""

    task: PrismHoleTask

    @abstractmethod
    def hole_edges(self) -> list[tuple[str, np.ndarray, float]]:
        """``(geom name, outward unit normal (2,), distance from the hole centre (m))`` per edge
        of the hole, in the hole frame."""

    @property
    @abstractmethod
    def hole_chamfer(self) -> float:
        """45-degree chamfer along the hole's entry edges (m)."""

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        p = self.task.params
        top = p.block_height
        z_bot = top - self.task.hole_depth
        block = fixture_body(scene, p.hole_yaw)
        half = [p.block_half_width, p.block_half_width, z_bot / 2]
        add_geom(block, "fixture_base", contact, type="box", size=half, pos=[0, 0, z_bot / 2])
        outline = rectangle(p.block_half_width, p.block_half_width)
        for name, normal, offset in self.hole_edges():
            verts = beyond_edge_block(outline, normal, offset, z_bot, top, self.hole_chamfer)
            add_mesh_geom(block, scene, name, verts, contact)
        for name, verts in self.hole_wards(z_bot, top):
            add_mesh_geom(block, scene, name, verts, contact)

    def hole_wards(self, z_bottom: float, z_top: float) -> list[tuple[str, np.ndarray]]:
        """``(geom name, vertices)`` of convex pieces that stand in the hole (hole frame at the
        block's foot, m): none by default."""
        del z_bottom, z_top
        return []


class PuzzleScene(PrismHoleScene):
    """``puzzle``: an equilateral triangular hole, no chamfer by default; a triangular piece."""

    task: Puzzle

    @property
    def held_part_length(self) -> float:
        return self.task.params.piece_height

    @property
    def hole_chamfer(self) -> float:
        return self.task.params.hole_chamfer

    def hole_edges(self) -> list[tuple[str, np.ndarray, float]]:
        inradius = self.task.params.hole_inradius
        normals = edge_normals(3, TRIANGLE_PHASE)
        return [(f"hole_wall_{i}", n, inradius) for i, n in enumerate(normals)]

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        p = self.task.params
        tri = regular_polygon(3, p.piece_inradius, TRIANGLE_PHASE)
        piece = chamfered_prism(tri, p.piece_height)
        add_mesh_geom(body, scene, "puzzle_piece", piece, contact, "tool", mass="0.05")


class KeyScene(PrismHoleScene):
    """``key``: a rectangular chamfered slot with two wards; a grooved blade under a bow."""

    task: Key

    @property
    def held_part_length(self) -> float:
        return self.task.params.blade_length + self.task.params.bow_height

    @property
    def hole_chamfer(self) -> float:
        return self.task.params.slot_chamfer

    def hole_edges(self) -> list[tuple[str, np.ndarray, float]]:
        hx, hy = self.task.slot_half_size
        sides = {"east": (1.0, 0.0, hx), "west": (-1.0, 0.0, hx)}
        sides |= {"north": (0.0, 1.0, hy), "south": (0.0, -1.0, hy)}
        return [(f"slot_wall_{s}", np.array([a, b]), d) for s, (a, b, d) in sides.items()]

    def hole_wards(self, z_bottom: float, z_top: float) -> list[tuple[str, np.ndarray]]:
        """The keyway's two wards: ``ward_depth`` ridges into the slot from its north wall at
        the east end and from its south wall at the west end (a Z-shaped profile, 2-fold
        symmetric), each chamfered by ``ward_chamfer`` along its two slot-facing edges and
        reaching over the wall's entry chamfer so that the lock face stays flat there."""
        p = self.task.params
        if p.ward_depth == 0:
            return []
        hx, hy = self.task.slot_half_size
        x0, y0, out = p.profile_middle / 2 + p.clearance / 2, hy - p.ward_depth, p.slot_chamfer
        wards = []
        for name, sign in (("slot_ward_ne", 1.0), ("slot_ward_sw", -1.0)):
            corners = [[hx + out, y0], [hx + out, hy + out], [x0, hy + out], [x0, y0]]
            outline = sign * np.array(corners)
            edges = [(np.array([sign, 0.0]), x0), (np.array([0.0, sign]), y0)]
            verts = chamfered_block(outline, edges, z_bottom, z_top, p.ward_chamfer)
            wards.append((name, verts))
        return wards

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        p = self.task.params
        pieces = self.task.blade_pieces()
        for name, poly in pieces:
            verts = chamfered_prism(poly, p.blade_length, p.blade_chamfer)
            mass = f"{0.005 / len(pieces):.6g}"  # 5 g of blade in all
            add_mesh_geom(body, scene, name, verts, contact, "tool", mass=mass)
        bow = [p.bow_width / 2, p.bow_thickness / 2, p.bow_height / 2]
        pos = [0, 0, p.blade_length + p.bow_height / 2]
        add_geom(body, "key_bow", contact, "tool", type="box", size=bow, pos=pos, mass="0.01")
