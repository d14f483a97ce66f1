"""How faithful a convex decomposition is where it matters: the clearance of the hole.

Every convex piece covers its hull, so a decomposition can only add material; where it adds
material inside the hole it narrows (or closes) the clearance the part fits with. The check
measures the narrowest gap between the aligned held part's footprint and the hole walls down
to the success depth twice, against the exact mesh's sections and against the union of the
pieces' sections (:mod:`teachfit.tasks.mesh.sections`), in the hole frame (m). A decomposition
that keeps less than :data:`MIN_KEPT` of the clearance is an error, not a silent failure.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
import trimesh
from scipy.spatial import ConvexHull

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.sections import ENTRY_EPS, footprint, section

#: smallest fraction of the mesh's clearance the decomposition must keep
MIN_KEPT = 0.5


@dataclass(frozen=True)
class Fidelity:
    """Clearance per side (m) of the aligned part in the mesh and in the decomposition, and
    the pieces' total volume over the mesh's (>= 1; overlaps between pieces count twice)."""

    mesh_clearance: float
    pieces_clearance: float
    volume_ratio: float

    @property
    def kept(self) -> float:
        """Fraction of the clearance the decomposition keeps."""
        return self.pieces_clearance / self.mesh_clearance if self.mesh_clearance > 0 else 0.0

    def summary(self) -> str:
        """One line: both clearances in mm and the volume ratio."""
        return (
            f"hole clearance per side {1e3 * self.mesh_clearance:.3f} mm in the mesh, "
            f"{1e3 * self.pieces_clearance:.3f} mm after decomposition "
            f"({100 * self.kept:.0f} % kept); pieces' volume {self.volume_ratio:.3f} x mesh"
        )


def decomposition_fidelity(
    fixed: trimesh.Trimesh,
    pieces: list[np.ndarray],
    held_pieces: list[np.ndarray],
    success_depth: float,
    mesh_clearance: float,
) -> Fidelity:
    """The :class:`Fidelity` of ``pieces`` (vertex arrays, hole frame, m) of the fixed part
    ``fixed`` (hole frame) for the held part's pieces ``held_pieces`` (TCP frame)."""
    held_hulls = [trimesh.Trimesh(v).convex_hull for v in held_pieces]
    foot = shapely.unary_union([footprint(h, success_depth) for h in held_hulls])
    x0, y0, x1, y1 = foot.bounds
    near = [  # only pieces by the hole can narrow it
        v
        for v in pieces
        if v[:, 0].min() < x1 + 1e-3
        and v[:, 0].max() > x0 - 1e-3
        and v[:, 1].min() < y1 + 1e-3
        and v[:, 1].max() > y0 - 1e-3
        and v[:, 2].max() > -success_depth
        and v[:, 2].min() < 0.0
    ]
    hulls = [trimesh.Trimesh(v).convex_hull for v in near]
    zs = -np.linspace(ENTRY_EPS, success_depth, max(4, int(np.ceil(success_depth / 5e-4)) + 1))
    walls = shapely.unary_union([section(h, z) for h in hulls for z in zs])
    gap = 0.0 if walls.intersects(foot) else float(walls.distance(foot))
    if walls.is_empty:
        gap = float("inf")
    ratio = sum(float(ConvexHull(v).volume) for v in pieces) / float(fixed.volume)
    return Fidelity(mesh_clearance, gap, ratio)


def require_fidelity(fid: Fidelity, where: str) -> None:
    """Raise :class:`TaskError` where the decomposition closes (or nearly closes) the hole."""
    if fid.kept < MIN_KEPT:
        raise TaskError(
            f"{where}: the convex decomposition narrows the hole: {fid.summary()}; for a "
            'rectilinear part use [decomposition] method = "auto" (exact boxes), else lower '
            "threshold (e.g. 0.01) and raise max_pieces"
        )
