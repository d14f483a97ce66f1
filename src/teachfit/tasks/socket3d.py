"""``socket3d``: a two-pin plug into a recessed round socket with valleys (seed A, 3D).

Europlug-like plug: two round pins (``pin_diameter``, ``pin_spacing`` apart, rounded tips) under
a round plug body. Socket: a round recess (``recess_diameter`` x ``recess_depth``) whose wall
keeps the plug body inside it; its floor (flat top at ``floor_height``, world z) holds two holes
on the world x-axis at ``x = -pin_spacing / 2`` (the *small* hole, ``clearance_small``) and
``x = +pin_spacing / 2`` (the *large* hole, ``clearance_large``), both diametral clearances.
Each hole sits at the bottom of a valley: a faceted funnel falling ``valley_depth`` from the
floor at ``valley_radius`` to the hole edge, which guides a compliantly pushed pin into the
hole. The socket centre is at the world origin in x-y.

Frames. The TCP is the midpoint of the two pin tips, the plug's +z axis up; at ``rz = 0`` the
pins lie along the world x-axis, matching the holes. The hole frame (:attr:`hole2world`) is the
midpoint between the holes at the height of the hole entries (the valley bottoms, i.e.
``floor_height - valley_depth``; the floor itself when ``valley_depth = 0``), z up, so
:meth:`insertion_depth` is how deep the pins are in their holes. The plug is two-fold
symmetric: ``rz = pi`` inserts as well (each pin then enters the other hole; the pins are equal,
so :meth:`ground_truth_inserted` accepts both). The search is in x, y and rz.

Convex pieces (MuJoCo collides meshes as convex hulls): per hole a square tile of half-width
``pin_spacing / 2`` split into ``n_wedges`` valley wedges (the tiles meet between the holes),
four prisms fill the rest of the floor, ``n_wall_sectors`` ring sectors form the recess wall,
a cylinder below forms the hole bottoms. The holes are shallower than the pins reach, so a
fully inserted plug stands on its pin tips and its body never seats on the ~40 floor pieces
(which would cost ~100 contacts per step).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.tasks.base import ContactParams, Task
from teachfit.tasks.mjcf import SceneXml, chamfered_cylinder, contact_attrs, fmt, ring_sector
from teachfit.tasks.socket_geometry import disc_segment, rounded_pin, valley_wedge


def _doc(text: str, default: float | int) -> float | int:
    return field(default=default, metadata={"doc": text})


@dataclass(frozen=True)
class Socket3DParams:
    """Parameters of :class:`Socket3D`; every length in metres, angles in radians."""

    pin_diameter: float = _doc("diameter of each pin (m)", 0.004)
    pin_spacing: float = _doc("distance between the pin (and hole) axes (m)", 0.019)
    pin_length: float = _doc("length of the pins below the plug body (m)", 0.019)
    pin_tip_radius: float = _doc("radius of the rounded pin-tip edge (m)", 0.0008)
    clearance_small: float = _doc("diametral clearance of the small hole, at -x (m)", 0.0004)
    clearance_large: float = _doc("diametral clearance of the large hole, at +x (m)", 0.0008)
    hole_depth: float = _doc("depth of the holes below their entry (m)", 0.016)
    valley_depth: float = _doc("depth of the valley from the floor to the hole edge (m)", 0.0025)
    valley_radius: float = _doc("radius around a hole where its valley meets the floor (m)", 0.006)
    recess_diameter: float = _doc("inner diameter of the socket recess (m)", 0.044)
    recess_depth: float = _doc("height of the recess wall above the floor (m)", 0.022)
    wall_thickness: float = _doc("thickness of the recess wall (m)", 0.005)
    floor_height: float = _doc("height of the recess floor's flat top (m, world z)", 0.050)
    body_diameter: float = _doc("diameter of the round plug body (m)", 0.027)
    body_height: float = _doc("height of the plug body above the pins (m)", 0.015)
    success_depth: float = _doc("pin insertion past the hole entry that counts (m)", 0.010)
    start_rz: float = _doc("starts draw rz uniformly within +-start_rz (rad)", 0.6981317)
    start_wall_gap: float = _doc("gap between plug body and wall at teacher starts (m)", 0.001)
    n_wedges: int = _doc("convex valley wedges around each hole", 16)
    n_wall_sectors: int = _doc("convex sectors forming the recess wall", 32)

    def __post_init__(self) -> None:
        positive = [
            "pin_diameter",
            "pin_spacing",
            "pin_length",
            "clearance_small",
            "clearance_large",
            "hole_depth",
            "valley_radius",
            "recess_diameter",
            "recess_depth",
            "wall_thickness",
            "floor_height",
            "body_diameter",
            "body_height",
            "success_depth",
            "start_rz",
        ]
        for name in positive:
            if not getattr(self, name) > 0:
                raise TaskError(f"socket3d: {name} must be > 0, got {getattr(self, name)}")
        for name in ("pin_tip_radius", "valley_depth", "start_wall_gap"):
            if getattr(self, name) < 0:
                raise TaskError(f"socket3d: {name} must be >= 0, got {getattr(self, name)}")
        self._check_holes()
        self._check_plug()

    def _check_holes(self) -> None:
        if self.clearance_large < self.clearance_small:
            raise TaskError(
                f"socket3d: clearance_large ({self.clearance_large}) must be >= clearance_small "
                f"({self.clearance_small})"
            )
        if self.clearance_large >= self.pin_diameter:
            raise TaskError("socket3d: clearances must be smaller than the pin diameter")
        r_large = (self.pin_diameter + self.clearance_large) / 2
        r_small = (self.pin_diameter + self.clearance_small) / 2
        if self.pin_spacing < r_large + r_small + 0.002:
            raise TaskError(
                f"socket3d: pin_spacing {self.pin_spacing} leaves less than 2 mm between holes "
                f"of radii {r_small:.4f} and {r_large:.4f} m"
            )
        rim = self.pin_spacing / 2 * np.cos(np.pi / max(self.n_wedges, 1))
        if not r_large < self.valley_radius <= rim:
            raise TaskError(
                f"socket3d: valley_radius must lie in ({r_large:.4f}, {rim:.4f}] m: beyond the "
                f"large hole's radius and inside the tiles (half the pin spacing), got "
                f"{self.valley_radius}"
            )
        if self.floor_height < self.valley_depth + self.hole_depth + 0.002:
            raise TaskError(
                "socket3d: floor_height must exceed valley_depth + hole_depth by >= 2 mm "
                "(the base under the holes)"
            )
        if self.success_depth > self.hole_depth:
            raise TaskError(
                f"socket3d: success_depth {self.success_depth} is deeper than the holes "
                f"({self.hole_depth}): impossible to succeed"
            )
        if not 8 <= self.n_wedges <= 64:
            raise TaskError(f"socket3d: n_wedges must be within [8, 64], got {self.n_wedges}")
        if not 12 <= self.n_wall_sectors <= 128:
            raise TaskError(
                f"socket3d: n_wall_sectors must be within [12, 128], got {self.n_wall_sectors}"
            )

    def _check_plug(self) -> None:
        if self.pin_tip_radius >= self.pin_diameter / 2:
            raise TaskError("socket3d: pin_tip_radius must be smaller than the pin radius")
        reach = self.pin_length - self.valley_depth  # pin depth where the body meets the floor
        if self.hole_depth > reach - 0.0002:
            raise TaskError(
                f"socket3d: hole_depth {self.hole_depth} must be at least 0.2 mm less than "
                f"pin_length - valley_depth ({reach:.4f} m): the pins bottom out in the holes "
                "before the plug body meets the floor (seating the body on the ~40 floor pieces "
                "would cost ~100 contacts)"
            )
        if self.body_diameter < self.pin_spacing + self.pin_diameter:
            raise TaskError("socket3d: body_diameter must cover both pins (>= spacing + diameter)")
        free = (self.recess_diameter - self.body_diameter) / 2
        if free < self.start_wall_gap + 0.001:
            raise TaskError(
                f"socket3d: the plug body (diameter {self.body_diameter}) leaves {free:.4f} m "
                f"of play in the recess (diameter {self.recess_diameter}); need > 1 mm plus "
                "start_wall_gap"
            )
        if self.recess_depth < self.pin_length + 0.001:
            raise TaskError(
                "socket3d: recess_depth must exceed pin_length by >= 1 mm so that the wall "
                "keeps the plug body inside the recess while the pins rest on the floor"
            )
        outer = self.recess_diameter / 2 + self.wall_thickness
        if np.hypot(self.pin_spacing, self.pin_spacing / 2) > outer:
            raise TaskError(
                "socket3d: the floor tiles around the holes reach beyond the socket's outer "
                "radius: increase recess_diameter or wall_thickness"
            )
        if self.start_rz >= np.pi / 2:
            raise TaskError("socket3d: start_rz must be below pi/2 (rz and rz+pi are equivalent)")


class Socket3D(Task):
    """Two-pin plug into a recessed socket with valleys; search in x, y and rz."""

    name = "socket3d"
    description = "two-pin plug into a recessed socket with valleys; search x-y-rz (seed A, 3D)"
    search_dims = ("x", "y", "rz")
    params_type = Socket3DParams
    params: Socket3DParams
    #: the plug is two-fold symmetric: it inserts at rz and at rz + pi (rad)
    rz_period: ClassVar[float] = float(np.pi)

    # ----------------------------------------------------------------------------- geometry
    @property
    def surface_z(self) -> float:
        return self.params.floor_height

    @property
    def hole2world(self) -> Pose:
        return Pose(np.array([0.0, 0.0, self.params.floor_height - self.params.valley_depth]))

    @property
    def success_depth(self) -> float:
        return self.params.success_depth

    @property
    def capture_radius(self) -> float:
        return self.params.clearance_large + 1e-4

    @property
    def held_part_length(self) -> float:
        return self.params.pin_length + self.params.body_height

    @property
    def hole_radii(self) -> tuple[float, float]:
        """Radii (m) of the small hole (at -x) and the large hole (at +x)."""
        p = self.params
        return (p.pin_diameter + p.clearance_small) / 2, (p.pin_diameter + p.clearance_large) / 2

    @property
    def hole_xy(self) -> np.ndarray:
        """Hole centres (2, 2) in the hole frame's x-y (m): small hole first."""
        half = self.params.pin_spacing / 2
        return np.array([[-half, 0.0], [half, 0.0]])

    @property
    def play(self) -> float:
        """How far (m) the plug centre can move from the socket centre inside the recess."""
        return (self.params.recess_diameter - self.params.body_diameter) / 2

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        half = p.pin_spacing / 2
        z_entry = p.floor_height - p.valley_depth
        z_bot = z_entry - p.hole_depth
        r_in = p.recess_diameter / 2
        r_out = r_in + p.wall_thickness
        kw = contact_attrs(contact)
        block = ET.SubElement(scene.worldbody, "body", name="fixture")
        ET.SubElement(
            block,
            "geom",
            name="socket_base",
            type="cylinder",
            size=fmt([r_out, z_bot / 2]),
            pos=fmt([0, 0, z_bot / 2]),
            material="metal",
            **kw,
        )
        k = p.n_wedges
        for side, (sign, r_hole) in enumerate(zip((-1.0, 1.0), self.hole_radii, strict=True)):
            for i in range(k):
                verts = valley_wedge(
                    (sign * half, 0.0),
                    2 * np.pi * i / k,
                    2 * np.pi * (i + 1) / k,
                    r_hole,
                    half,
                    z_bot,
                    z_entry,
                    p.floor_height,
                    p.valley_radius,
                )
                scene.add_mesh(f"valley_{side}_{i}", verts)
                ET.SubElement(
                    block,
                    "geom",
                    name=f"valley_{side}_{i}",
                    type="mesh",
                    mesh=f"valley_{side}_{i}",
                    material="metal",
                    **kw,
                )
        fillers = {  # the floor outside the two tiles: x in [-2 half, 2 half], |y| <= half
            "north": [(0.0, 1.0, half)],
            "south": [(0.0, -1.0, half)],
            "east": [(1.0, 0.0, 2 * half), (0.0, 1.0, -half), (0.0, -1.0, -half)],
            "west": [(-1.0, 0.0, 2 * half), (0.0, 1.0, -half), (0.0, -1.0, -half)],
        }
        for name, planes in fillers.items():
            scene.add_mesh(f"floor_{name}", disc_segment(r_out, z_bot, p.floor_height, planes))
            ET.SubElement(
                block,
                "geom",
                name=f"floor_{name}",
                type="mesh",
                mesh=f"floor_{name}",
                material="metal",
                **kw,
            )
        rim = p.floor_height + p.recess_depth
        scene.add_mesh("recess_wall", ring_sector(r_in, r_out, z_bot, rim, p.n_wall_sectors))
        for i in range(p.n_wall_sectors):
            ET.SubElement(
                block,
                "geom",
                name=f"recess_wall_{i}",
                type="mesh",
                mesh="recess_wall",
                euler=fmt([0, 0, 2 * np.pi * i / p.n_wall_sectors]),
                material="metal",
                **kw,
            )

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        p = self.params
        kw = contact_attrs(contact)
        scene.add_mesh("pin", rounded_pin(p.pin_diameter / 2, p.pin_length, p.pin_tip_radius))
        for name, x in (("pin_small", -p.pin_spacing / 2), ("pin_large", p.pin_spacing / 2)):
            ET.SubElement(
                body,
                "geom",
                name=name,
                type="mesh",
                mesh="pin",
                pos=fmt([x, 0, 0]),
                material="tool",
                mass="0.01",
                **kw,
            )
        # a convex mesh, not a primitive cylinder: MuJoCo gives a cylinder up to 4 contacts per
        # floor piece, a mesh one, which keeps the plug seated on ~30 pieces cheap to simulate
        scene.add_mesh(
            "plug_body", chamfered_cylinder(p.body_diameter / 2, p.body_height, 0.001, 32)
        )
        ET.SubElement(
            body,
            "geom",
            name="plug_body",
            type="mesh",
            mesh="plug_body",
            pos=fmt([0, 0, p.pin_length]),
            material="tool",
            mass="0.08",
            **kw,
        )

    # ------------------------------------------------------------------------- ground truth
    def pin_tips(self, tool2world: Pose) -> np.ndarray:
        """Pin-tip centres (2, 3) in the hole frame (m): the -x pin first at ``rz = 0``."""
        rel = self.hole2world.inverse().compose(tool2world)
        local = np.column_stack([self.hole_xy, np.zeros(2)])  # pins match holes at rz = 0
        return rel.rotation.apply(local) + rel.pos

    def ground_truth_inserted(self, tool2world: Pose) -> bool:
        """Both pins are deeper than :attr:`success_depth` and each lies in a hole.

        Either assignment of pins to holes counts (``rz`` near 0 or pi): the pins are equal.
        """
        tips = self.pin_tips(tool2world)
        p = self.params
        holes = self.hole_xy
        tol = np.array([p.clearance_small, p.clearance_large]) + 1e-4
        if np.any(-tips[:, 2] < self.success_depth):
            return False
        for order in ((0, 1), (1, 0)):
            lateral = np.linalg.norm(tips[list(order), :2] - holes, axis=1)
            if np.all(lateral < tol):
                return True
        return False

    # ---------------------------------------------------------------------------- protocols
    def search_pose(self, state: np.ndarray, search2world: Pose, height: float = 0.0) -> Pose:
        s = np.asarray(state, dtype=float)
        if s.shape != (3,):
            raise TaskError(f"socket3d search states are (x, y, rz), got shape {s.shape}")
        return search2world.compose(Pose.from_xyz_rz(s[0], s[1], height, s[2]))

    def _in_valley(self, pose: Pose) -> bool:
        """Whether a pin tip starts inside a valley (it would be guided in at once)."""
        tips = self.pin_tips(pose)[:, :2]
        holes = self.hole_xy
        dist = np.linalg.norm(tips[:, None, :] - holes[None, :, :], axis=2)
        return bool(np.any(dist < self.params.valley_radius))

    def teacher_start(self, rng: np.random.Generator) -> Pose:
        """Plug inside the recess, ``start_wall_gap`` from the wall, in the upper half (y >= 0).

        The direction from the socket centre is uniform over the upper half, rz uniform within
        ``+-start_rz``; draws whose pins start inside a valley are redrawn (up to 100 times).
        The pins rest on the floor (TCP at :attr:`surface_z`).
        """
        dist = self.play - self.params.start_wall_gap
        pose = self.contact_pose(np.zeros(2))
        for _ in range(100):
            ang = rng.uniform(0.0, np.pi)
            rz = rng.uniform(-self.params.start_rz, self.params.start_rz)
            pose = self.contact_pose(dist * np.array([np.cos(ang), np.sin(ang)]), rz)
            if not self._in_valley(pose):
                break
        return pose

    def protocol_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None = None
    ) -> list[Pose]:
        """Starts for seed A's 3D protocol.

        ``"table3"``: ``n`` starts (the paper used 15) uniform over the socket's upper half: the
        plug centre uniform in the half disc ``y > 0`` of radius :attr:`play` minus 0.5 mm (the
        body never touches the wall), rz uniform within ``+-start_rz``. ``"teacher"``: worst-case
        starts like the blind teacher's. ``demo_start`` is not used.
        """
        del demo_start
        if n <= 0:
            raise TaskError(f"number of starts must be positive, got {n}")
        if protocol == "teacher":
            return [self.teacher_start(rng) for _ in range(n)]
        if protocol != "table3":
            raise TaskError(f"socket3d has protocols teacher, table3; not {protocol!r}")
        radius = self.play - 0.0005
        r = radius * np.sqrt(rng.uniform(0.0, 1.0, n))
        a = rng.uniform(0.0, np.pi, n)
        rz = rng.uniform(-self.params.start_rz, self.params.start_rz, n)
        return [
            self.contact_pose(ri * np.array([np.cos(ai), np.sin(ai)]), zi)
            for ri, ai, zi in zip(r, a, rz, strict=True)
        ]
