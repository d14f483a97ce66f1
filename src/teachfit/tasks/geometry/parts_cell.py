"""The planning parts as a MuJoCo cell: convex boxes, the fixed part placed by a capture error.

:mod:`teachfit.tasks.parts` builds the L-groove and tenon parts as unions and differences of
boxes (for mesh-mesh planning). MuJoCo collides each geom as a convex solid, so here the same
solids are cut directly into disjoint boxes -- the fixed groove into floor, side walls, end
walls and lip; each mortise into the four bars around its square hole; the L into base and leg;
the tenon into bar and shoulder -- whose union is exactly the planning mesh (checked by volume
in the tests). No general convex decomposition is needed for these parts.

:class:`PartsCell` is a :class:`~teachfit.tasks.base.Task` over such a cell so that the one
robot registry and execution engine run it: the held part's TCP is the moving part's frame
``L``, the fixture body is the fixed part's frame ``G`` placed at its *true* pose
``G2world = nominal ∘ error`` (the capture error, a task parameter), and the "hole" is where
``L`` ends: ``G2world ∘ goal``. The robot knows only the captured (nominal) pose.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose, quat_angle, rotation_to_wxyz
from teachfit.tasks.base import Task
from teachfit.tasks.parts import Assembly, LGrooveParams, TenonParams, part_assembly
from teachfit.tasks.protocols.base import Protocol
from teachfit.tasks.scene.builder import SceneBuilder, add_geom
from teachfit.tasks.scene.mjcf import ContactParams, SceneXml, fmt

Box = tuple[tuple[float, float, float], tuple[float, float, float]]  # low and high corner, m

#: where the nominal fixed-part frame G sits in the world (m): on a table 5 cm up
G_NOMINAL = Pose(np.array([0.0, 0.0, 0.05]))


def l_groove_boxes(p: LGrooveParams) -> tuple[list[Box], list[Box]]:
    """Disjoint boxes of the L (frame L) and of the groove (frame G); see the module docs."""
    b, t, w = p.base_length, p.base_thickness, p.width
    moving = [
        ((0.0, -w / 2, 0.0), (b, w / 2, t)),
        ((b - p.leg_thickness, -w / 2, t), (b, w / 2, t + p.leg_height)),
    ]
    lc, d, wc, wall = p.cavity_length, p.cavity_depth, w + 2 * p.clearance, p.wall
    top = d + p.lip_thickness
    x0, x1, y0, y1 = -lc / 2 - wall, lc / 2 + wall, -wc / 2 - wall, wc / 2 + wall
    fixed = [
        ((x0, y0, -wall), (x1, y1, 0.0)),  # floor
        ((x0, wc / 2, 0.0), (x1, y1, top)),  # side walls
        ((x0, y0, 0.0), (x1, -wc / 2, top)),
        ((x0, -wc / 2, 0.0), (-lc / 2, wc / 2, top)),  # end walls
        ((lc / 2, -wc / 2, 0.0), (x1, wc / 2, top)),
        ((-lc / 2, -wc / 2, d), (p.opening_start, wc / 2, top)),  # lip
    ]
    return moving, fixed


def tenon_boxes(p: TenonParams) -> tuple[list[Box], list[Box]]:
    """Disjoint boxes of the tenon (frame L) and of the two mortises (frame G)."""
    a, s = p.bar_side, p.shoulder_side
    moving = [
        ((0.0, -a / 2, -a / 2), (p.bar_length, a / 2, a / 2)),
        ((p.bar_length, -s / 2, -s / 2), (p.bar_length + p.shoulder_length, s / 2, s / 2)),
    ]
    m, side, zc, h = p.mortise_thickness, p.mortise_side, p.hole_height, a + 2 * p.clearance
    fixed: list[Box] = []
    for x0 in (0.0, m + p.mortise_gap):
        fixed += [
            ((x0, -side / 2, 0.0), (x0 + m, side / 2, zc - h / 2)),  # below the hole
            ((x0, -side / 2, zc + h / 2), (x0 + m, side / 2, side)),  # above
            ((x0, -side / 2, zc - h / 2), (x0 + m, -h / 2, zc + h / 2)),  # beside
            ((x0, h / 2, zc - h / 2), (x0 + m, side / 2, zc + h / 2)),
        ]
    return moving, fixed


def part_boxes(part: str) -> tuple[list[Box], list[Box]]:
    """``(moving, fixed)`` boxes of the planning part ``part`` (default dimensions)."""
    if part == "l-groove":
        return l_groove_boxes(LGrooveParams())
    if part == "tenon":
        return tenon_boxes(TenonParams())
    raise TaskError(f"no MuJoCo cell for part {part!r}; known: l-groove, tenon")


@dataclass(frozen=True)
class PartsCellParams:
    """The cell: which part, the fixed part's capture error (m, rad; applied in frame G as
    translation then extrinsic x-y-z rotation) and the friction coefficient."""

    task_name: ClassVar[str] = "parts-cell"

    part: str = "l-groove"
    dx: float = 0.0
    dy: float = 0.0
    dz: float = 0.0
    droll: float = 0.0
    dpitch: float = 0.0
    dyaw: float = 0.0
    friction: float = 0.3

    def __post_init__(self) -> None:
        if self.part not in ("l-groove", "tenon"):
            raise TaskError(f"part must be 'l-groove' or 'tenon', got {self.part!r}")

    @property
    def error(self) -> Pose:
        """The capture error as a pose in frame G."""
        from scipy.spatial.transform import Rotation

        rot = Rotation.from_euler("xyz", [self.droll, self.dpitch, self.dyaw])
        return Pose(np.array([self.dx, self.dy, self.dz]), rotation_to_wxyz(rot))


class PartsScene(SceneBuilder):
    """Fixed part as static boxes at the true ``G2world``; the held part's boxes in ``L``."""

    task: PartsCell

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        g = self.task.g2world
        body = ET.SubElement(
            scene.worldbody, "body", name="fixture", pos=fmt(g.pos), quat=fmt(g.quat)
        )
        for i, box in enumerate(self.task.boxes[1]):
            _box_geom(body, f"fixed{i}", box, contact, "metal")

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        for i, box in enumerate(self.task.boxes[0]):
            _box_geom(body, f"part{i}", box, contact, "tool")

    @property
    def held_part_length(self) -> float:
        return max(hi[2] for _, hi in self.task.boxes[0]) + 0.005


def _box_geom(body: ET.Element, name: str, box: Box, contact: ContactParams, mat: str) -> None:
    lo, hi = np.asarray(box[0]), np.asarray(box[1])
    add_geom(body, name, contact, mat, type="box", pos=(lo + hi) / 2, size=(hi - lo) / 2)


class PartsProtocol(Protocol):
    """A planning cell has no blind-search protocol: its start is the plan's."""

    names = ()

    def teacher_start(self, rng: np.random.Generator) -> Pose:
        raise TaskError("the parts cell has no blind-teacher start: execute a plan instead")

    def paper_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None
    ) -> list[Pose]:
        raise TaskError(f"the parts cell has no protocol {protocol!r}")


class PartsCell(Task):
    """An L-groove or tenon cell in MuJoCo (see the module docstring)."""

    name = "parts-cell"
    description = "a planning part (L-groove, tenon) held by the robot, fixed part as captured"
    search_dims = ("x", "y")
    params_type = PartsCellParams
    scene_type = PartsScene
    protocol_type = PartsProtocol
    params: PartsCellParams

    #: ground truth tolerances: along the insertion (G x), across it (m), orientation (rad)
    tol_along, tol_across, tol_angle = 0.003, 0.006, math.radians(4.0)

    @cached_property
    def assembly(self) -> Assembly:
        return part_assembly(self.params.part)

    @cached_property
    def boxes(self) -> tuple[list[Box], list[Box]]:
        return part_boxes(self.params.part)

    @property
    def g2world(self) -> Pose:
        """The fixed part's true pose: the nominal one composed with the capture error."""
        return G_NOMINAL.compose(self.params.error)

    @property
    def goal_l2g(self) -> Pose:
        return Pose.from_matrix(self.assembly.goal)

    @property
    def surface_z(self) -> float:
        return float(G_NOMINAL.pos[2] + self.assembly.bounds[1, 2])

    @property
    def hole2world(self) -> Pose:
        return self.g2world.compose(self.goal_l2g)

    @property
    def nominal_hole2world(self) -> Pose:
        return G_NOMINAL.compose(self.goal_l2g)

    @property
    def success_depth(self) -> float:
        return self.tol_along

    @property
    def detection_radius(self) -> float:
        return self.tol_across

    def ground_truth_inserted(self, tool2world: Pose) -> bool:
        """The part within the tolerances of its goal in the *true* fixed-part frame."""
        rel = self.g2world.compose(self.goal_l2g).inverse().compose(tool2world)
        g_rel = self.goal_l2g.rotation.apply(np.array(rel.pos))  # the error along G axes
        return bool(
            abs(g_rel[0]) <= self.tol_along
            and np.hypot(g_rel[1], g_rel[2]) <= self.tol_across
            and quat_angle(rel.quat, np.array([1.0, 0.0, 0.0, 0.0])) <= self.tol_angle
        )
