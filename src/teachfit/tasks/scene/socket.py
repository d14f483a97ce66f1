"""Scene of the ``socket3d`` cell: a recessed round socket with two valley holes; a plug.

Convex pieces (MuJoCo collides meshes as convex hulls): per hole a square tile of half-width
``pin_spacing / 2`` split into ``n_wedges`` valley wedges
(:func:`~teachfit.tasks.scene.socket_pieces.valley_wedge`; the tiles meet between the holes),
four prisms fill the rest of the floor, ``n_wall_sectors`` ring sectors form the recess wall,
a cylinder below forms the hole bottoms. The plug is two rounded pins (TCP at the midpoint of
their tips, along the plug's x) under a round body. World frame z up, lengths in metres.
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
from teachfit.tasks.scene.socket_pieces import disc_segment, rounded_pin, valley_wedge

if TYPE_CHECKING:
    from teachfit.tasks.geometry.socket3d import Socket3D


class SocketScene(SceneBuilder):
    """The socket (fixture) and the two-pin plug (held part) of :class:`Socket3D`."""

    task: Socket3D

    @property
    def held_part_length(self) -> float:
        return self.task.params.pin_length + self.task.params.body_height

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        p = self.task.params
        half = p.pin_spacing / 2
        z_entry = self.task.entry_height
        z_bot = z_entry - p.hole_depth
        r_in = p.recess_diameter / 2
        r_out = r_in + p.wall_thickness
        block = fixture_body(scene)
        add_geom(
            block,
            "socket_base",
            contact,
            type="cylinder",
            size=[r_out, z_bot / 2],
            pos=[0, 0, z_bot / 2],
        )
        k = p.n_wedges
        for side, (sign, r_hole) in enumerate(zip((-1.0, 1.0), self.task.hole_radii, strict=True)):
            for i in range(k):
                a0, a1 = 2 * np.pi * i / k, 2 * np.pi * (i + 1) / k
                verts = valley_wedge(
                    (sign * half, 0.0),
                    a0,
                    a1,
                    r_hole,
                    half,
                    z_bot,
                    z_entry,
                    p.floor_height,
                    p.valley_radius,
                )
                add_mesh_geom(block, scene, f"valley_{side}_{i}", verts, contact)
        fillers = {  # the floor outside the two tiles: x in [-2 half, 2 half], |y| <= half
            "north": [(0.0, 1.0, half)],
            "south": [(0.0, -1.0, half)],
            "east": [(1.0, 0.0, 2 * half), (0.0, 1.0, -half), (0.0, -1.0, -half)],
            "west": [(-1.0, 0.0, 2 * half), (0.0, 1.0, -half), (0.0, -1.0, -half)],
        }
        for name, planes in fillers.items():
            verts = disc_segment(r_out, z_bot, p.floor_height, planes)
            add_mesh_geom(block, scene, f"floor_{name}", verts, contact)
        wall = ring_sector(r_in, r_out, z_bot, p.floor_height + p.recess_depth, p.n_wall_sectors)
        add_ring(block, scene, "recess_wall", wall, p.n_wall_sectors, "recess_wall_", contact)

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        p = self.task.params
        scene.add_mesh("pin", rounded_pin(p.pin_diameter / 2, p.pin_length, p.pin_tip_radius))
        for name, x in (("pin_small", -p.pin_spacing / 2), ("pin_large", p.pin_spacing / 2)):
            add_geom(
                body, name, contact, "tool", type="mesh", mesh="pin", pos=[x, 0, 0], mass="0.01"
            )
        # a convex mesh, not a primitive cylinder: MuJoCo gives a cylinder up to 4 contacts per
        # floor piece, a mesh one, which keeps the plug seated on ~30 pieces cheap to simulate
        plug = chamfered_cylinder(p.body_diameter / 2, p.body_height, 0.001, 32)
        pos = [0, 0, p.pin_length]
        add_mesh_geom(body, scene, "plug_body", plug, contact, "tool", pos=pos, mass="0.08")
