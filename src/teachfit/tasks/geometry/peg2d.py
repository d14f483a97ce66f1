"""``peg2d``: a round peg searching on the flat top of a cylinder with a round hole (Ehlers et al.
2019, 2D).

The fixture is a cylinder of diameter ``block_diameter`` whose top holds a round hole of
diameter ``peg_diameter + clearance`` (diametral clearance) and depth ``hole_depth``, centred at
the world origin. The hole wall is built from ``n_sectors`` convex ring sectors (MuJoCo collides
meshes as convex hulls, :mod:`teachfit.tasks.scene.round_hole`); the polygonal hole
circumscribes the nominal circle so it is never narrower than asked. Orientation is held fixed:
the search is in x-y.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar

from teachfit.core.teaching import TeacherHints
from teachfit.tasks.base import Task
from teachfit.tasks.geometry.round_peg import RoundPegParams
from teachfit.tasks.params import doc_field
from teachfit.tasks.protocols.ehlers import Peg2DProtocol
from teachfit.tasks.scene.round_hole import Peg2DScene

#: the blind teacher's defaults (m, N/m, m/s) and the load it slides (push + peg weight, N)
#: at the default friction, which its default sweep suits (see Peg2D.teacher_hints)
DEFAULT_PITCH, DEFAULT_HALFWIDTH, DEFAULT_FRICTION = 0.0025, 0.015, 0.3
TEACHER_STIFFNESS, TEACHER_SPEED, TEACHER_LOAD = 600.0, 0.012, 7.0
#: a search's tilt for sharp-edged holes (rad), and the capture half-width (m) of a peg so
#: tilted: straight passes with Ø 8 mm, 0.2 mm clearance, μ 0.5-0.8 drop in up to 1-2 mm off
#: the axis (0.1 mm upright). Holes whose upright capture is wider (chamfered: >= 1.6 mm) are
#: searched upright, as before
SEARCH_TILT, TILTED_CAPTURE = 0.25, 0.001
GRAVITY = 9.81  # m/s^2


@dataclass(frozen=True)
class Peg2DParams(RoundPegParams):
    """Parameters of :class:`Peg2D`; every length in metres."""

    task_name: ClassVar[str] = "peg2d"

    peg_diameter: float = doc_field("peg diameter (m)", 0.020, above=0)
    clearance: float = doc_field(
        "diametral clearance: hole diameter minus peg diameter (m)", 5e-4, above=0
    )
    hole_depth: float = doc_field("depth of the hole below the top surface (m)", 0.020, above=0)
    peg_length: float = doc_field("length of the peg below the wrist sensor (m)", 0.060, above=0)
    peg_chamfer: float = doc_field("45-degree chamfer on the peg tip edge (m)", 0.001, at_least=0)
    hole_chamfer: float = doc_field(
        "45-degree chamfer on the hole entry edge (m)", 0.0005, at_least=0
    )
    block_diameter: float = doc_field(
        "diameter of the cylinder holding the hole (m)", 0.120, above=0
    )
    block_height: float = doc_field("height of that cylinder's top surface (m)", 0.060, above=0)
    success_depth: float = doc_field("insertion depth that counts as success (m)", 0.010, above=0)
    demo_offset: float = doc_field(
        "distance of the blind teacher's worst-case start (m)", 0.030, above=0
    )
    friction: float = doc_field("sliding friction coefficient peg/block", 0.3, at_least=0)
    n_sectors: int = doc_field("convex sectors forming the hole wall", 32)

    def check(self) -> None:
        self.require(
            self.clearance < self.peg_diameter, "clearance must be smaller than the peg diameter"
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
        self.require(
            self.demo_offset + self.peg_diameter / 2 < self.block_diameter / 2,
            "demo_offset puts the teacher's start off the block",
        )
        self.check_round_peg()


class Peg2D(Task):
    """Round peg into a round hole on top of a cylinder; search in x-y, orientation fixed."""

    name = "peg2d"
    description = (
        "round peg into a round hole on a cylinder top; search x-y "
        "(Ehlers et al. 2019, Tables I-II)"
    )
    search_dims = ("x", "y")
    params_type = Peg2DParams
    scene_type = Peg2DScene
    protocol_type = Peg2DProtocol
    params: Peg2DParams
    scene: Peg2DScene

    @property
    def surface_z(self) -> float:
        return self.params.block_height

    @property
    def detection_radius(self) -> float:
        """The peg's footprint stays on the cylinder top within its radius minus the peg's."""
        return (self.params.block_diameter - self.params.peg_diameter) / 2

    @property
    def capture_halfwidth(self) -> float:
        """Lateral TCP offset (m) within which a pressed peg drops in: the radial clearance
        plus both chamfers' widths (straight passes drop in up to 1.5 mm off with the default
        1 mm and 0.5 mm chamfers, up to ~0.1 mm off with sharp edges and 0.2 mm clearance)."""
        p = self.params
        return p.clearance / 2 + p.peg_chamfer + p.hole_chamfer

    @property
    def hold_depth(self) -> float:
        """Sinking (m) that means the peg is in the bore: both chamfers' depth plus 0.5 mm."""
        return self.params.peg_chamfer + self.params.hole_chamfer + 0.0005

    @property
    def search_hold_depth(self) -> float:
        """Sinking (m) at which a search executor stops moving the peg sideways: the hole's
        chamfer plus 0.5 mm. The peg's flat tip (radius ``r - peg_chamfer``) only gets below
        the hole's chamfer inside the bore, i.e. within ``clearance / 2 + peg_chamfer`` of
        the axis, where pressed down with a soft hand its own chamfer centres it; dragged on
        from there at high friction it wedges on the bore's edge at the chamfers' depth
        (1.5 mm by default, short of :attr:`hold_depth`)."""
        return self.params.hole_chamfer + 0.0005

    @property
    def stiffness_scale(self) -> float:
        """Factor (>= 1) on a follower's lateral stiffness that keeps the sliding peg's lag
        behind its set-point what it is at the default friction: the lag is ``friction *
        load / stiffness``, so the stiffness grows with the friction above the default's
        (0.8: x 2.67; with a 6 N push along the motion 1.2 mm instead of 3.2 mm at 1500 N/m,
        across it 12 mm instead of 32 mm at 150 N/m; at or below the default friction: 1, the
        default cell's follower unchanged). Too soft a follower on a
        high-friction top cuts a tour's turns by the lag and misses holes the plan crosses."""
        return max(1.0, self.params.friction / DEFAULT_FRICTION)

    @property
    def search_tilt(self) -> float:
        """Tilt (rad) of a searching peg: :data:`SEARCH_TILT` where the upright capture
        half-width is under the tilted one, :data:`TILTED_CAPTURE` (sharp edges), else 0."""
        return SEARCH_TILT if self.capture_halfwidth < TILTED_CAPTURE else 0.0

    @property
    def jam_free_tilt(self) -> float:
        """The largest tilt (rad) at which a peg turning upright about the hole's far edge
        clears the near edge with its high rim at any depth: ``acos(r / R)`` for peg radius
        ``r`` and hole radius ``R = r + clearance / 2`` (Ø 30 mm, 0.3 mm: 0.14 rad;
        :mod:`teachfit.skills.tilt`, jams)."""
        r = 0.5 * self.params.peg_diameter
        return math.acos(r / (r + 0.5 * self.params.clearance))

    def sliding_friction(self, push: float) -> float:
        """Friction force (N) on the peg sliding on the top pressed with ``push`` (N): the
        friction coefficient times the push plus the peg's weight (2.1 N at the default 0.3
        and a 6 N push)."""
        return self.params.friction * (push + GRAVITY * self.scene.peg_mass)

    def teacher_hints(self) -> TeacherHints:
        """The blind teacher's sweep scaled to this cell (m, s).

        The defaults (rows 2.5 mm apart, 15 mm half-width, 60 s) suit the default cell. Rows
        are at most 1.6 capture half-widths apart, so that a pass always crosses the hole
        where the peg drops in; the half-width grows by the extra friction lag of the
        sliding peg over the default friction's (``friction * (push + weight) / stiffness``:
        within it of a turn the peg sticks instead of sliding); the time budget grows with
        the raster's length (up to 10 minutes); the teacher stops moving the peg sideways
        once it sank :attr:`hold_depth` (a hand that feels the drop). Where the search
        tilts (:attr:`search_tilt`, sharp edges), the teacher tilts too and its rows are
        1.6 tilted capture half-widths apart.
        """
        tilt = self.search_tilt
        capture = TILTED_CAPTURE if tilt > 0 else self.capture_halfwidth
        pitch = min(DEFAULT_PITCH, 1.6 * capture)
        lag = (self.params.friction - DEFAULT_FRICTION) * TEACHER_LOAD / TEACHER_STIFFNESS
        half = DEFAULT_HALFWIDTH + max(0.0, lag)
        rows = (self.params.demo_offset + half) / pitch + 1  # start to past the hole
        duration = rows * (2 * half + pitch) / TEACHER_SPEED
        hints = TeacherHints(
            spiral_pitch=pitch,
            sweep_halfwidth=half,
            max_duration=float(min(600.0, max(60.0, duration))),
            hold_depth=self.hold_depth,
        )
        if tilt > 0:  # sharp edges: the hand tilts the peg as the searcher does and slides
            reach = self.params.peg_diameter + self.params.clearance  # it across the hole
            hints = dataclasses.replace(hints, tilt=tilt, tilt_reach=reach)
        return hints
