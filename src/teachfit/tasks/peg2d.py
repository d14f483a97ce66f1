"""``peg2d``: a round peg searching on the flat top of a cylinder with a round hole (seed A, 2D).

The fixture is a cylinder of diameter ``block_diameter`` whose top holds a round hole of
diameter ``peg_diameter + clearance`` (diametral clearance) and depth ``hole_depth``, centred at
the world origin. The hole wall is built from ``n_sectors`` convex ring sectors (MuJoCo collides
meshes as convex hulls); the polygonal hole circumscribes the nominal circle so it is never
narrower than asked. Orientation is held fixed: the search is in x-y.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.tasks.base import ContactParams, Task
from teachfit.tasks.mjcf import SceneXml, chamfered_cylinder, contact_attrs, fmt, ring_sector


def _doc(text: str, default: float | int) -> float | int:
    return field(default=default, metadata={"doc": text})


@dataclass(frozen=True)
class Peg2DParams:
    """Parameters of :class:`Peg2D`; every length in metres."""

    peg_diameter: float = _doc("peg diameter (m)", 0.020)
    clearance: float = _doc("diametral clearance: hole diameter minus peg diameter (m)", 0.0005)
    hole_depth: float = _doc("depth of the hole below the top surface (m)", 0.020)
    peg_length: float = _doc("length of the peg below the wrist sensor (m)", 0.060)
    peg_chamfer: float = _doc("45-degree chamfer on the peg tip edge (m)", 0.001)
    hole_chamfer: float = _doc("45-degree chamfer on the hole entry edge (m)", 0.0005)
    block_diameter: float = _doc("diameter of the cylinder holding the hole (m)", 0.120)
    block_height: float = _doc("height of that cylinder's top surface (m)", 0.060)
    success_depth: float = _doc("insertion depth that counts as success (m)", 0.010)
    demo_offset: float = _doc("distance of the blind teacher's worst-case start (m)", 0.030)
    friction: float = _doc("sliding friction coefficient peg/block", 0.3)
    n_sectors: int = _doc("convex sectors forming the hole wall", 32)

    def __post_init__(self) -> None:
        positive = [
            "peg_diameter",
            "clearance",
            "hole_depth",
            "peg_length",
            "block_diameter",
            "block_height",
            "success_depth",
            "demo_offset",
        ]
        for name in positive:
            if not getattr(self, name) > 0:
                raise TaskError(f"peg2d: {name} must be > 0, got {getattr(self, name)}")
        for name in ("peg_chamfer", "hole_chamfer", "friction"):
            if getattr(self, name) < 0:
                raise TaskError(f"peg2d: {name} must be >= 0, got {getattr(self, name)}")
        if self.clearance >= self.peg_diameter:
            raise TaskError("peg2d: clearance must be smaller than the peg diameter")
        if self.peg_chamfer >= self.peg_diameter / 2:
            raise TaskError("peg2d: peg_chamfer must be smaller than the peg radius")
        hole_r = (self.peg_diameter + self.clearance) / 2 + self.hole_chamfer
        if self.block_diameter / 2 <= hole_r + 0.005:
            raise TaskError(
                f"peg2d: block_diameter {self.block_diameter} leaves no rim around a hole of "
                f"radius {hole_r:.4f} m (need at least 5 mm)"
            )
        if self.hole_depth >= self.block_height:
            raise TaskError("peg2d: hole_depth must be smaller than block_height")
        if self.success_depth > self.hole_depth:
            raise TaskError(
                f"peg2d: success_depth {self.success_depth} is deeper than the hole "
                f"({self.hole_depth}): impossible to succeed"
            )
        if self.peg_length <= self.hole_depth:
            raise TaskError("peg2d: peg_length must exceed hole_depth")
        if self.demo_offset + self.peg_diameter / 2 >= self.block_diameter / 2:
            raise TaskError("peg2d: demo_offset puts the teacher's start off the block")
        if not 8 <= self.n_sectors <= 256:
            raise TaskError("peg2d: n_sectors must be within [8, 256]")


class Peg2D(Task):
    """Round peg into a round hole on top of a cylinder; search in x-y, orientation fixed."""

    name = "peg2d"
    description = "round peg into a round hole on a cylinder top; search x-y (seed A, 2D)"
    search_dims = ("x", "y")
    params_type = Peg2DParams
    params: Peg2DParams

    @property
    def surface_z(self) -> float:
        return self.params.block_height

    @property
    def hole2world(self) -> Pose:
        return Pose(np.array([0.0, 0.0, self.surface_z]))

    @property
    def success_depth(self) -> float:
        return self.params.success_depth

    @property
    def capture_radius(self) -> float:
        return self.params.clearance + 1e-4

    @property
    def held_part_length(self) -> float:
        return self.params.peg_length

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        hole_r = (p.peg_diameter + p.clearance) / 2
        outer_r = p.block_diameter / 2
        z_bot = p.block_height - p.hole_depth
        scene.add_mesh(
            "hole_sector",
            ring_sector(hole_r, outer_r, z_bot, p.block_height, p.n_sectors, p.hole_chamfer),
        )
        block = ET.SubElement(scene.worldbody, "body", name="fixture")
        geom_kw = contact_attrs(contact)
        ET.SubElement(
            block,
            "geom",
            name="fixture_base",
            type="cylinder",
            size=fmt([outer_r, z_bot / 2]),
            pos=fmt([0, 0, z_bot / 2]),
            material="metal",
            **geom_kw,
        )
        for i in range(p.n_sectors):
            ang = 2 * np.pi * i / p.n_sectors
            ET.SubElement(
                block,
                "geom",
                name=f"hole_wall_{i}",
                type="mesh",
                mesh="hole_sector",
                euler=fmt([0, 0, ang]),
                material="metal",
                **geom_kw,
            )

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        scene.add_mesh(
            "peg", chamfered_cylinder(p.peg_diameter / 2, p.peg_length, p.peg_chamfer, 48)
        )
        ET.SubElement(
            body,
            "geom",
            name="peg",
            type="mesh",
            mesh="peg",
            material="tool",
            mass="0.1",
            **contact_attrs(contact),
        )

    def search_pose(self, state: np.ndarray, search2world: Pose, height: float = 0.0) -> Pose:
        s = np.asarray(state, dtype=float)
        if s.shape != (2,):
            raise TaskError(f"peg2d search states are (x, y), got shape {s.shape}")
        tool2search = Pose(np.array([s[0], s[1], height]))
        return search2world.compose(tool2search)

    def teacher_start(self, rng: np.random.Generator) -> Pose:
        ang = rng.uniform(0, 2 * np.pi)
        xy = self.params.demo_offset * np.array([np.cos(ang), np.sin(ang)])
        return self.contact_pose(xy)

    def protocol_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None = None
    ) -> list[Pose]:
        """Starts for seed A's 2D protocols.

        ``"table1"``: ``n`` starts uniform in a 3 cm-diameter circle centred halfway between the
        demonstration's start and the hole. ``"table2"``: ``n`` copies of that centre.
        ``"teacher"``: worst-case starts like the blind teacher's.
        """
        if n <= 0:
            raise TaskError(f"number of starts must be positive, got {n}")
        if protocol == "teacher":
            return [self.teacher_start(rng) for _ in range(n)]
        if protocol not in ("table1", "table2"):
            raise TaskError(f"peg2d has protocols teacher, table1, table2; not {protocol!r}")
        start = (
            demo_start
            if demo_start is not None
            else self.contact_pose(np.array([self.params.demo_offset, 0.0]))
        )
        centre = (start.pos[:2] + self.hole2world.pos[:2]) / 2
        if protocol == "table2":
            return [self.contact_pose(centre)] * n
        r = 0.015 * np.sqrt(rng.uniform(0, 1, n))
        a = rng.uniform(0, 2 * np.pi, n)
        return [
            self.contact_pose(centre + ri * np.array([np.cos(ai), np.sin(ai)]))
            for ri, ai in zip(r, a, strict=True)
        ]
