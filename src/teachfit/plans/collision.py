"""Collision and distance between a moving part ``L`` and fixed parts ``G`` (coal).

Two exact representations of the same solids:

- meshes (any part, e.g. a mesh task's): BVHs (OBBRSS) built once, mesh-mesh tests. coal
  tests each pair of triangles whose bounding volumes overlap with GJK, so a pose a fraction
  of a millimetre from contact costs ~0.1-0.4 ms (the planner's hot spot, most of its poses
  are near contact). Mesh-mesh tests only see surfaces: a part lying entirely inside the
  other's solid would pass; the parts here cannot hide inside each other.
- boxes, for parts that are unions of boxes (the parametric L-groove and tenon, whose meshes
  are built as those unions): coal's box primitives in its dynamic AABB-tree broad phase,
  one C++ call per moving box, ~10 µs whatever the distance, and volumetric (a box inside
  another collides).

Distances (reports only) always use the meshes.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import coal
import numpy as np
import trimesh

from teachfit.core.errors import PlanningError
from teachfit.core.geometry import quat_normalize_into, quat_to_matrix_into

if TYPE_CHECKING:
    from teachfit.tasks.parts import Assembly

__all__ = [
    "CollisionChecker",
    "box_corners",
    "pose_to_matrix",
    "quat_to_matrix",
    "validate_mesh",
]


def quat_to_matrix(w: float, x: float, y: float, z: float) -> np.ndarray:
    """(3, 3) rotation matrix of a quaternion (w, x, y, z), normalised first.

    Through the geometry kernel's MuJoCo-backed :func:`quat_to_matrix_into` (a few µs, against
    ~100 µs for a scipy ``Rotation`` round trip): this sits on the planner's hot path.
    """
    q = np.array((w, x, y, z), dtype=float)
    if quat_normalize_into(q) == 0.0:
        raise PlanningError("zero quaternion")
    return quat_to_matrix_into(np.empty(9), q).reshape(3, 3)


def pose_to_matrix(pos: np.ndarray, quat: np.ndarray) -> np.ndarray:
    """(4, 4) homogeneous transform from a position (3,) in m and a quaternion (4,) w-x-y-z."""
    T = np.eye(4)
    T[:3, :3] = quat_to_matrix(*(float(q) for q in quat))
    T[:3, 3] = pos
    return T


def validate_mesh(mesh: trimesh.Trimesh, name: str) -> None:
    """Raise :class:`PlanningError` for a mesh no collision check can trust.

    Rejected: no triangles, non-finite vertices, zero-area triangles, a zero-size bounding box.
    """
    vertices = np.asarray(mesh.vertices, dtype=float)
    faces = np.asarray(mesh.faces)
    if faces.ndim != 2 or len(faces) == 0 or len(vertices) < 3:
        raise PlanningError(f"{name} mesh is degenerate: it has no triangles")
    if not np.all(np.isfinite(vertices)):
        raise PlanningError(f"{name} mesh is degenerate: non-finite vertex coordinates")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise PlanningError(f"{name} mesh is degenerate: face indices out of range")
    tri = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    extent = float(np.ptp(vertices, axis=0).max())
    if extent <= 0 or np.any(area <= 1e-12 * extent**2):
        raise PlanningError(
            f"{name} mesh is degenerate: {int(np.sum(area <= 1e-12 * extent**2))} zero-area "
            "triangle(s) or zero extent"
        )


def _bvh(mesh: trimesh.Trimesh) -> coal.BVHModelOBBRSS:
    model = coal.BVHModelOBBRSS()
    vertices = np.asarray(mesh.vertices, dtype=float)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    model.beginModel(len(faces), len(vertices))
    verts = coal.StdVec_Vec3s()
    verts.extend(list(vertices))
    tris = coal.StdVec_Triangle()
    tris.extend([coal.Triangle(int(a), int(b), int(c)) for a, b, c in faces])
    model.addSubModel(verts, tris)
    model.endModel()
    return model


def box_corners(boxes: object, name: str) -> np.ndarray:
    """(N, 2, 3) low and high corners (m) of axis-aligned boxes, checked non-empty."""
    b = np.asarray(boxes, dtype=float)
    if b.ndim != 3 or b.shape[1:] != (2, 3) or len(b) == 0 or not np.all(np.isfinite(b)):
        raise PlanningError(f"{name} boxes must be a finite (N, 2, 3) array, got {b.shape}")
    if np.any(b[:, 1] <= b[:, 0]):
        raise PlanningError(f"{name} boxes must have high corners above their low corners")
    return b


def _box_objects(boxes: np.ndarray) -> list[coal.CollisionObject]:
    return [
        coal.CollisionObject(coal.Box(*(hi - lo)), coal.Transform3s(np.eye(3), (lo + hi) / 2))
        for lo, hi in boxes
    ]


class CollisionChecker:
    """Collision and distance queries of a moving mesh against a fixed one.

    Parameters
    ----------
    moving : trimesh.Trimesh
        Moving part in its own frame ``L`` (m).
    fixed : trimesh.Trimesh
        Fixed part(s) in frame ``G`` (m); its transform is the identity.
    margin : float
        Security margin (m): poses closer than this count as colliding. 0 by default.
    boxes : (moving, fixed) pair of (N, 2, 3) arrays, optional
        The same parts as unions of axis-aligned boxes (low, high corners; m, in ``L`` and in
        ``G``): collision tests then use the boxes (see the module docstring).

    Attributes
    ----------
    n_checks : int
        Number of collision checks made so far.
    """

    def __init__(
        self,
        moving: trimesh.Trimesh,
        fixed: trimesh.Trimesh,
        *,
        margin: float = 0.0,
        boxes: tuple[np.ndarray, np.ndarray] | None = None,
    ):
        validate_mesh(moving, "moving")
        validate_mesh(fixed, "fixed")
        if not np.isfinite(margin) or margin < 0:
            raise PlanningError(f"margin must be >= 0 m, got {margin!r}")
        self._moving = _bvh(moving)
        self._fixed = _bvh(fixed)
        self._collide = coal.ComputeCollision(self._moving, self._fixed)
        self._distance = coal.ComputeDistance(self._moving, self._fixed)
        self._creq = coal.CollisionRequest()
        self._creq.security_margin = float(margin)
        self._cres = coal.CollisionResult()
        self._dreq = coal.DistanceRequest()
        self._dres = coal.DistanceResult()
        self._L2G = coal.Transform3s()
        self._q = np.zeros(4)  # buffers of the hot path: quaternion and rotation (row-major)
        self._R9 = np.zeros(9)
        self._t = np.zeros(3)
        self._G = coal.Transform3s()
        self.n_checks = 0
        self._margin = float(margin)
        self._boxes: list[tuple[coal.CollisionObject, coal.Transform3s]] | None = None
        if boxes is not None:
            mov, fix = box_corners(boxes[0], "moving"), box_corners(boxes[1], "fixed")
            self._manager = coal.DynamicAABBTreeCollisionManager()
            for obj in _box_objects(fix):
                self._manager.registerObject(obj)
            self._manager.setup()
            offsets = [coal.Transform3s(np.eye(3), (lo + hi) / 2) for lo, hi in mov]
            self._boxes = list(zip(_box_objects(mov), offsets, strict=True))
            self._moving_tree = coal.DynamicAABBTreeCollisionManager()
            for obj, _ in self._boxes:
                self._moving_tree.registerObject(obj)
            self._moving_tree.setup()
            self._callback = coal.CollisionCallBackDefault()
            self._callback.data.request.enable_contact = False
            self._callback.data.request.security_margin = self._margin
            self._widen = np.full(3, self._margin)

    @property
    def on_boxes(self) -> bool:
        """True when the collision tests use the parts' boxes (else their meshes)."""
        return self._boxes is not None

    @classmethod
    def of(cls, asm: Assembly, *, margin: float = 0.0) -> CollisionChecker:
        """The checker of an assembly (``moving``, ``fixed`` meshes), on its boxes where it has
        them (``moving_boxes`` and ``fixed_boxes`` not None)."""
        mov, fix = asm.moving_boxes, asm.fixed_boxes
        boxes = None if mov is None or fix is None else (mov, fix)
        return cls(asm.moving, asm.fixed, margin=margin, boxes=boxes)

    def collides_xyzq(
        self, x: float, y: float, z: float, w: float, qx: float, qy: float, qz: float
    ) -> bool:
        """Collision test for ``L2G`` given as position (m) and quaternion w-x-y-z (hot path)."""
        t = self._t
        t[0], t[1], t[2] = x, y, z
        if self._boxes is not None:  # scalar arithmetic: no array round trip on this path
            norm = math.sqrt(w * w + qx * qx + qy * qy + qz * qz)
            if not norm > 1e-15:
                raise PlanningError("zero quaternion")
            self._L2G.setQuatRotation(coal.Quaternion(w / norm, qx / norm, qy / norm, qz / norm))
        else:
            q = self._q
            q[0], q[1], q[2], q[3] = w, qx, qy, qz
            if quat_normalize_into(q) == 0.0:
                raise PlanningError("zero quaternion")
            self._L2G.setRotation(quat_to_matrix_into(self._R9, q).reshape(3, 3))
        self._L2G.setTranslation(t)
        return self._check()

    def collides(self, L2G: np.ndarray) -> bool:
        """Collision test for a (4, 4) pose ``L2G`` of the moving part in ``G``."""
        self._set(L2G)
        return self._check()

    def _check(self) -> bool:
        """Collision test at the pose already set; counted in ``n_checks``."""
        self.n_checks += 1
        if self._boxes is None:
            self._cres.clear()
            self._collide(self._L2G, self._G, self._creq, self._cres)
            return self._cres.isCollision()
        for obj, offset in self._boxes:
            obj.setTransform(self._L2G * offset)
            obj.computeAABB()
            if self._margin > 0:  # the broad phase must see pairs up to the margin apart
                obj.getAABB().expand(self._widen)
        self._moving_tree.update()
        self._callback.init()
        self._manager.collide(self._moving_tree, self._callback)  # one call: tree against tree
        return self._callback.data.result.isCollision()

    def distance(self, L2G: np.ndarray) -> float:
        """Minimum distance (m) between the parts at pose ``L2G``; <= 0 when they touch."""
        self._set(L2G)
        self._dres.clear()
        self._distance(self._L2G, self._G, self._dreq, self._dres)
        return float(self._dres.min_distance)

    def _set(self, L2G: np.ndarray) -> None:
        T = np.asarray(L2G, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise PlanningError(f"L2G must be a finite (4, 4) transform, got shape {T.shape}")
        self._L2G.setRotation(np.ascontiguousarray(T[:3, :3]))
        self._L2G.setTranslation(np.ascontiguousarray(T[:3, 3]))
