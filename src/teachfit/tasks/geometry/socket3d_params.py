"""Parameters of the ``socket3d`` cell and their validation (lengths in metres, angles in rad).

See :mod:`teachfit.tasks.geometry.socket3d` for the geometry they describe.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from teachfit.tasks.params import TaskParams, doc_field


@dataclass(frozen=True)
class Socket3DParams(TaskParams):
    """Parameters of :class:`~teachfit.tasks.geometry.socket3d.Socket3D`."""

    task_name: ClassVar[str] = "socket3d"

    pin_diameter: float = doc_field("diameter of each pin (m)", 0.004, above=0)
    pin_spacing: float = doc_field("distance between the pin (and hole) axes (m)", 0.019, above=0)
    pin_length: float = doc_field("length of the pins below the plug body (m)", 0.019, above=0)
    pin_tip_radius: float = doc_field("radius of the rounded pin-tip edge (m)", 0.0008, at_least=0)
    clearance_small: float = doc_field(
        "diametral clearance of the small hole, at -x (m)", 0.0004, above=0
    )
    clearance_large: float = doc_field(
        "diametral clearance of the large hole, at +x (m)", 0.0008, above=0
    )
    hole_depth: float = doc_field("depth of the holes below their entry (m)", 0.016, above=0)
    valley_depth: float = doc_field(
        "depth of the valley from the floor to the hole edge (m)", 0.0025, at_least=0
    )
    valley_radius: float = doc_field(
        "radius around a hole where its valley meets the floor (m)", 0.006, above=0
    )
    recess_diameter: float = doc_field("inner diameter of the socket recess (m)", 0.044, above=0)
    recess_depth: float = doc_field("height of the recess wall above the floor (m)", 0.022, above=0)
    wall_thickness: float = doc_field("thickness of the recess wall (m)", 0.005, above=0)
    floor_height: float = doc_field(
        "height of the recess floor's flat top (m, world z)", 0.050, above=0
    )
    body_diameter: float = doc_field("diameter of the round plug body (m)", 0.027, above=0)
    body_height: float = doc_field("height of the plug body above the pins (m)", 0.015, above=0)
    success_depth: float = doc_field(
        "pin insertion past the hole entry that counts (m)", 0.010, above=0
    )
    start_rz: float = doc_field(
        "starts draw rz uniformly within +-start_rz (rad)", 0.6981317, above=0
    )
    start_wall_gap: float = doc_field(
        "gap between plug body and wall at teacher starts (m)", 0.001, at_least=0
    )
    n_wedges: int = doc_field("convex valley wedges around each hole", 16)
    n_wall_sectors: int = doc_field("convex sectors forming the recess wall", 32)

    def check(self) -> None:
        self._check_holes()
        self._check_plug()

    def _check_holes(self) -> None:
        self.require(
            self.clearance_large >= self.clearance_small,
            f"clearance_large ({self.clearance_large}) must be >= clearance_small "
            f"({self.clearance_small})",
        )
        self.require(
            self.clearance_large < self.pin_diameter,
            "clearances must be smaller than the pin diameter",
        )
        r_large = (self.pin_diameter + self.clearance_large) / 2
        r_small = (self.pin_diameter + self.clearance_small) / 2
        self.require(
            self.pin_spacing >= r_large + r_small + 0.002,
            f"pin_spacing {self.pin_spacing} leaves less than 2 mm between holes "
            f"of radii {r_small:.4f} and {r_large:.4f} m",
        )
        rim = self.pin_spacing / 2 * np.cos(np.pi / max(self.n_wedges, 1))
        self.require(
            r_large < self.valley_radius <= rim,
            f"valley_radius must lie in ({r_large:.4f}, {rim:.4f}] m: beyond the large hole's "
            f"radius and inside the tiles (half the pin spacing), got {self.valley_radius}",
        )
        self.require(
            self.floor_height >= self.valley_depth + self.hole_depth + 0.002,
            "floor_height must exceed valley_depth + hole_depth by >= 2 mm "
            "(the base under the holes)",
        )
        self.require_reachable(self.success_depth, self.hole_depth, "holes")
        self.require(
            8 <= self.n_wedges <= 64, f"n_wedges must be within [8, 64], got {self.n_wedges}"
        )
        self.require(
            12 <= self.n_wall_sectors <= 128,
            f"n_wall_sectors must be within [12, 128], got {self.n_wall_sectors}",
        )

    def _check_plug(self) -> None:
        self.require(
            self.pin_tip_radius < self.pin_diameter / 2,
            "pin_tip_radius must be smaller than the pin radius",
        )
        reach = self.pin_length - self.valley_depth  # pin depth where the body meets the floor
        self.require(
            self.hole_depth <= reach - 0.0002,
            f"hole_depth {self.hole_depth} must be at least 0.2 mm less than "
            f"pin_length - valley_depth ({reach:.4f} m): the pins bottom out in the holes "
            "before the plug body meets the floor (seating the body on the ~40 floor pieces "
            "would cost ~100 contacts)",
        )
        self.require(
            self.body_diameter >= self.pin_spacing + self.pin_diameter,
            "body_diameter must cover both pins (>= spacing + diameter)",
        )
        free = (self.recess_diameter - self.body_diameter) / 2
        self.require(
            free >= self.start_wall_gap + 0.001,
            f"the plug body (diameter {self.body_diameter}) leaves {free:.4f} m of play in the "
            f"recess (diameter {self.recess_diameter}); need > 1 mm plus start_wall_gap",
        )
        self.require(
            self.recess_depth >= self.pin_length + 0.001,
            "recess_depth must exceed pin_length by >= 1 mm so that the wall keeps the plug "
            "body inside the recess while the pins rest on the floor",
        )
        outer = self.recess_diameter / 2 + self.wall_thickness
        self.require(
            np.hypot(self.pin_spacing, self.pin_spacing / 2) <= outer,
            "the floor tiles around the holes reach beyond the socket's outer radius: increase "
            "recess_diameter or wall_thickness",
        )
        self.require(
            self.start_rz < np.pi / 2, "start_rz must be below pi/2 (rz and rz+pi are equivalent)"
        )
