"""Parametric parts for planning: an L-part with a closed groove, a tenon with two mortises.

The built-in tasks ``l-groove`` and ``tenon`` (Wang et al. 2019); the task registry
(:func:`teachfit.tasks.registry.build_assembly`) gives their assemblies and those of mesh task
files, :class:`~teachfit.tasks.geometry.parts_cell.PartsCell` their MuJoCo cells.

Every assembly is expressed in the frame ``G`` of its fixed part. The moving part's frame ``L``
is attached to its mesh as documented per task, and the planner searches over ``L2G``, the pose
of ``L`` in ``G``.

L-groove (docs/methods.md, Wang et al. 2019; the paper's Fig. 3)
    ``G``: origin at the centre of the cavity floor, x along the groove, z up. The cavity is
    closed at both ends and covered by a lip on its -x side; the exposed opening (length
    ``opening_length``, at the +x end of the cavity) is shorter than the L's base, so the L must
    be tilted in with its -x end first, pivoted about a contact and slid under the lip.
    ``L``: origin at the bottom edge of the base's -x end (the pivot edge), x along the base,
    z along the leg, which stands at the base's +x end.

Tenon (paper Sec. IV)
    ``G``: two mortises, walls normal to x, each with a square through-hole centred on the
    line y = 0, z = ``hole_height``; origin at the -x face of the far mortise, at floor level.
    ``L``: origin at the centre of the tenon's leading (-x) end face; the bar runs along +x
    and ends in a wider shoulder. The tenon goes through the near mortise, then the far one.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING

import manifold3d
import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from teachfit.core.errors import TaskError

if TYPE_CHECKING:  # trimesh is imported where a mesh is built: 0.4 s of every command's start
    import trimesh

__all__ = [
    "PARTS",
    "Assembly",
    "LGrooveParams",
    "PaperResult",
    "TenonParams",
    "part_assembly",
    "pose_from_xyz_rpy",
]


def pose_from_xyz_rpy(xyz: ArrayLike, rpy_deg: ArrayLike) -> np.ndarray:
    """4x4 homogeneous transform from a position (m) and extrinsic x-y-z Euler angles (deg)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy_deg, degrees=True).as_matrix()
    T[:3, 3] = xyz
    return T


@dataclass(frozen=True)
class PaperResult:
    """What the paper's Table I reports for a task (Wang, Harada, Wan 2019)."""

    candidates: int
    used: tuple[int, int]
    time_s: tuple[float, float]


@dataclass(frozen=True, eq=False)
class Assembly:
    """A planning task: meshes, start and goal poses, sampling bounds.

    Attributes
    ----------
    task : str
        Registry name (``"l-groove"`` or ``"tenon"``).
    moving, fixed : trimesh.Trimesh
        Meshes of the moving part in frame ``L`` and of the fixed part(s) in frame ``G``, in m.
    start, goal : np.ndarray
        (4, 4) ``L2G`` initial and final poses (the paper's P_I and P_F), collision-free.
    bounds : np.ndarray
        (2, 3) low/high corners, in m and frame ``G``, of the box the ``L`` origin is sampled in.
    key_param : str
        Pose parameter ranked by :mod:`teachfit.plans.keyposes` (``"pitch"`` for the L, as in
        the paper; ``"auto"`` picks the most-changing one).
    n_candidates : int
        Number of candidate key poses taken from a demonstration (paper: 6 and 11).
    key_region : float
        Candidates are taken where the demonstrated part is closer than this (m) to the fixed
        part: the paper's "important area" (A to B in its Fig. 6).
    dimensions : Mapping[str, float]
        Named dimensions in m, for figures and reports.
    paper : PaperResult
        The paper's Table I numbers for this task.
    moving_boxes, fixed_boxes : np.ndarray or None
        (N, 2, 3) low/high corners (m) of axis-aligned boxes whose union is the moving part
        (in ``L``) and the fixed part (in ``G``): the meshes are built as these unions, and
        the collision checks test the boxes (:class:`~teachfit.plans.collision.CollisionChecker`).
        None for parts given only as meshes.
    """

    task: str
    moving: trimesh.Trimesh
    fixed: trimesh.Trimesh
    start: np.ndarray
    goal: np.ndarray
    bounds: np.ndarray
    key_param: str
    n_candidates: int
    key_region: float
    dimensions: Mapping[str, float]
    paper: PaperResult
    moving_boxes: np.ndarray | None = None
    fixed_boxes: np.ndarray | None = None


def _box(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> manifold3d.Manifold:
    size = [h - low for low, h in zip(lo, hi, strict=True)]
    return manifold3d.Manifold.cube(size).translate(list(lo))


Corners = tuple[tuple[float, float, float], tuple[float, float, float]]


def _union(boxes: list[Corners]) -> tuple[np.ndarray, trimesh.Trimesh]:
    """(N, 2, 3) corners and the mesh of a union of boxes given as (low, high) corners (m)."""
    corners = np.asarray(boxes, dtype=float)
    return corners, _to_trimesh(
        manifold3d.Manifold.batch_boolean(
            [_box(tuple(lo), tuple(hi)) for lo, hi in corners], manifold3d.OpType.Add
        )
    )


def _to_trimesh(solid: manifold3d.Manifold) -> trimesh.Trimesh:
    # manifold3d does the boolean algebra (exact, watertight output); trimesh carries the result.
    import trimesh

    mesh = solid.to_mesh()
    out = trimesh.Trimesh(
        vertices=np.asarray(mesh.vert_properties)[:, :3].astype(float),
        faces=np.asarray(mesh.tri_verts).astype(np.int64),
        process=True,
    )
    if len(out.faces) == 0 or not out.is_watertight or out.volume <= 0:
        raise TaskError("part mesh is degenerate (empty, not watertight or zero volume)")
    return out


def _check_positive(params: object, names: tuple[str, ...]) -> None:
    for name in names:
        value = getattr(params, name)
        if not np.isfinite(value) or value <= 0:
            raise TaskError(f"{type(params).__name__}.{name} must be > 0 m, got {value!r}")


@dataclass(frozen=True)
class LGrooveParams:
    """Dimensions (m) of the L-part and its closed groove.

    Defaults make the passage narrow: the opening (70 mm) is shorter than the base (100 mm),
    the L has 1.5 mm of clearance per side across the groove, and the base only passes the
    opening's edges in a thin band of tilts and positions (a plain RRT-Connect finds no path
    in 20 s, see BENCHMARKS.md).
    """

    base_length: float = 0.100
    base_thickness: float = 0.008
    width: float = 0.030
    leg_height: float = 0.035
    leg_thickness: float = 0.008
    clearance: float = 0.0015
    opening_length: float = 0.070
    cavity_depth: float = 0.020
    length_slack: float = 0.006
    lip_thickness: float = 0.006
    wall: float = 0.010

    def __post_init__(self) -> None:
        _check_positive(self, tuple(self.__dataclass_fields__))
        if self.opening_length >= self.base_length:
            raise TaskError(
                "opening_length must be shorter than base_length (else no pivot is needed): "
                f"{self.opening_length} >= {self.base_length}"
            )
        if self.cavity_depth <= self.base_thickness:
            raise TaskError("cavity_depth must exceed base_thickness")
        if self.leg_thickness >= self.base_length:
            raise TaskError("leg_thickness must be smaller than base_length")
        if self.leg_thickness + 2 * self.length_slack >= self.opening_length:
            raise TaskError("the leg does not fit through the opening")

    @property
    def cavity_length(self) -> float:
        """Inner length (m) of the groove along x."""
        return self.base_length + self.length_slack

    @property
    def opening_start(self) -> float:
        """x (m, frame G) of the lip's edge, where the opening begins."""
        return self.cavity_length / 2 - self.opening_length

    def build(self) -> Assembly:
        """Meshes, start/goal poses and bounds of the L-groove task."""
        b, t, w = self.base_length, self.base_thickness, self.width
        moving_boxes, moving = _union(
            [
                ((0.0, -w / 2, 0.0), (b, w / 2, t)),  # base
                ((b - self.leg_thickness, -w / 2, t), (b, w / 2, t + self.leg_height)),  # leg
            ]
        )
        lc, d, wc = self.cavity_length, self.cavity_depth, w + 2 * self.clearance
        top, e, y = d + self.lip_thickness, self.wall, wc / 2
        # a block with the cavity and, above its +x end, the opening cut out, as six boxes
        fixed_boxes, fixed = _union(
            [
                ((-lc / 2 - e, -y - e, -e), (lc / 2 + e, y + e, 0.0)),  # floor
                ((-lc / 2 - e, y, 0.0), (lc / 2 + e, y + e, top)),  # side walls
                ((-lc / 2 - e, -y - e, 0.0), (lc / 2 + e, -y, top)),
                ((-lc / 2 - e, -y, 0.0), (-lc / 2, y, top)),  # end walls
                ((lc / 2, -y, 0.0), (lc / 2 + e, y, top)),
                ((-lc / 2, -y, d), (self.opening_start, y, top)),  # lip
            ]
        )

        z_rest = (d - t) / 2
        goal = pose_from_xyz_rpy(
            np.array([-lc / 2 + self.length_slack / 3, 0.0, z_rest]), [0, 0, 0]
        )
        start = pose_from_xyz_rpy(
            np.array([self.opening_start - 0.01, 0.0, top + 0.03]), np.array([0.0, 0.0, 0.0])
        )
        bounds = np.array(
            [[-lc / 2 - 0.005, -0.02, 0.0], [lc / 2 + 0.01, 0.02, top + 0.06]], dtype=float
        )
        dims = {
            "base_length": b,
            "base_thickness": t,
            "width": w,
            "leg_height": self.leg_height,
            "opening_length": self.opening_length,
            "cavity_length": lc,
            "cavity_depth": d,
            "lip_thickness": self.lip_thickness,
            "clearance": self.clearance,
        }
        return Assembly(
            task="l-groove",
            moving=moving,
            fixed=fixed,
            start=start,
            goal=goal,
            bounds=bounds,
            key_param="pitch",
            n_candidates=6,
            key_region=0.005,
            dimensions=MappingProxyType(dims),
            paper=PaperResult(candidates=6, used=(2, 3), time_s=(1.43, 3.03)),
            moving_boxes=moving_boxes,
            fixed_boxes=fixed_boxes,
        )


@dataclass(frozen=True)
class TenonParams:
    """Dimensions (m) of the tenon (square bar with a shoulder) and its two mortises."""

    bar_side: float = 0.020
    bar_length: float = 0.120
    shoulder_side: float = 0.036
    shoulder_length: float = 0.015
    clearance: float = 0.001
    mortise_thickness: float = 0.020
    mortise_gap: float = 0.040
    mortise_side: float = 0.070
    hole_height: float = 0.035

    def __post_init__(self) -> None:
        _check_positive(self, tuple(self.__dataclass_fields__))
        if self.shoulder_side <= self.bar_side + 2 * self.clearance:
            raise TaskError("shoulder_side must exceed the hole so the shoulder stops the tenon")
        hole = self.bar_side + 2 * self.clearance
        if hole >= self.mortise_side or self.hole_height - hole / 2 <= 0:
            raise TaskError("the hole does not fit inside the mortise")
        if self.hole_height + hole / 2 >= self.mortise_side:
            raise TaskError("hole_height puts the hole outside the mortise")
        if self.bar_length <= 2 * self.mortise_thickness + self.mortise_gap:
            raise TaskError("bar_length must span both mortises")

    def build(self) -> Assembly:
        """Meshes, start/goal poses and bounds of the tenon task."""
        a, s = self.bar_side, self.shoulder_side
        moving_boxes, moving = _union(
            [
                ((0.0, -a / 2, -a / 2), (self.bar_length, a / 2, a / 2)),  # bar
                (
                    (self.bar_length, -s / 2, -s / 2),
                    (self.bar_length + self.shoulder_length, s / 2, s / 2),
                ),  # shoulder
            ]
        )

        m, gap, side, zc = (
            self.mortise_thickness,
            self.mortise_gap,
            self.mortise_side,
            self.hole_height,
        )
        h, y = (a + 2 * self.clearance) / 2, side / 2
        boxes = []
        for x0 in (0.0, m + gap):  # each mortise: a block with a square hole, as four boxes
            x1 = x0 + m
            boxes += [
                ((x0, -y, 0.0), (x1, y, zc - h)),  # below the hole
                ((x0, -y, zc + h), (x1, y, side)),  # above it
                ((x0, -y, zc - h), (x1, -h, zc + h)),  # beside it
                ((x0, h, zc - h), (x1, y, zc + h)),
            ]
        fixed_boxes, fixed = _union(boxes)

        near_face = 2 * m + gap
        goal = pose_from_xyz_rpy(np.array([-0.006, 0.0, zc]), [0, 0, 0])
        start = pose_from_xyz_rpy(np.array([near_face + 0.06, 0.0, side + 0.05]), [0, -50, 30])
        bounds = np.array([[-0.02, -0.08, 0.0], [near_face + 0.12, 0.08, side + 0.09]], dtype=float)
        dims = {
            "bar_side": a,
            "bar_length": self.bar_length,
            "shoulder_side": s,
            "clearance": self.clearance,
            "mortise_thickness": m,
            "mortise_gap": gap,
            "hole_height": zc,
        }
        return Assembly(
            task="tenon",
            moving=moving,
            fixed=fixed,
            start=start,
            goal=goal,
            bounds=bounds,
            key_param="pitch",
            n_candidates=11,
            key_region=0.02,
            dimensions=MappingProxyType(dims),
            paper=PaperResult(candidates=11, used=(2, 5), time_s=(1.26, 2.66)),
            moving_boxes=moving_boxes,
            fixed_boxes=fixed_boxes,
        )


PARTS: Mapping[str, type[LGrooveParams] | type[TenonParams]] = MappingProxyType(
    {"l-groove": LGrooveParams, "tenon": TenonParams}
)
"""Task name -> parameter class; ``PARTS[name](**overrides).build()`` gives the assembly."""


def part_assembly(task: str, **overrides: float) -> Assembly:
    """The assembly of the built-in part ``task`` (``l-groove``, ``tenon``), with optional
    dimension overrides (m); :class:`TaskError` for an unknown part, dimension or value."""
    if task not in PARTS:
        raise TaskError(f"unknown task {task!r}; known: {', '.join(PARTS)} (or a mesh .toml)")
    cls = PARTS[task]
    unknown = set(overrides) - set(cls.__dataclass_fields__)
    if unknown:
        raise TaskError(f"unknown dimension(s) for {task}: {', '.join(sorted(unknown))}")
    return cls(**overrides).build()
