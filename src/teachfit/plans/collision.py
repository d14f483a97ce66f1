"""Mesh-mesh collision and distance between a moving part ``L`` and fixed parts ``G`` (coal).

The BVHs (OBBRSS) are built once; a query only updates the moving part's transform, so a
check from Python costs a few microseconds plus coal's narrow phase.

Mesh-mesh tests only see surfaces: a part lying entirely inside the other's solid would pass.
The parts here cannot hide inside each other (each moving part is larger than every solid
region of its fixed part in at least one direction), so surface tests suffice.
"""

from __future__ import annotations

import coal
import numpy as np
import trimesh

from teachfit.core.errors import PlanningError
from teachfit.core.geometry import quat_normalize_into, quat_to_matrix_into

__all__ = ["CollisionChecker", "pose_to_matrix", "quat_to_matrix", "validate_mesh"]


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

    Attributes
    ----------
    n_checks : int
        Number of collision checks made so far.
    """

    def __init__(self, moving: trimesh.Trimesh, fixed: trimesh.Trimesh, *, margin: float = 0.0):
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
        self._G = coal.Transform3s()
        self.n_checks = 0

    def collides_xyzq(
        self, x: float, y: float, z: float, w: float, qx: float, qy: float, qz: float
    ) -> bool:
        """Collision test for ``L2G`` given as position (m) and quaternion w-x-y-z (hot path)."""
        q = self._q
        q[0], q[1], q[2], q[3] = w, qx, qy, qz
        if quat_normalize_into(q) == 0.0:
            raise PlanningError("zero quaternion")
        self._L2G.setRotation(quat_to_matrix_into(self._R9, q).reshape(3, 3))
        self._L2G.setTranslation(np.array((x, y, z)))
        return self._check()

    def collides(self, L2G: np.ndarray) -> bool:
        """Collision test for a (4, 4) pose ``L2G`` of the moving part in ``G``."""
        self._set(L2G)
        return self._check()

    def _check(self) -> bool:
        """Collision test at the pose already set; counted in ``n_checks``."""
        self._cres.clear()
        self.n_checks += 1
        self._collide(self._L2G, self._G, self._creq, self._cres)
        return self._cres.isCollision()

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
