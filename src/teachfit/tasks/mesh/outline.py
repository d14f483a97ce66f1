"""The outline of a mesh task's hole, for figures: its real shape and size from the meshes.

The hole's outline is the void around the hole axis in the union of the fixed part's
sections from just below the entry down to the success depth (the narrowest the part passes
through, as in :func:`teachfit.tasks.mesh.sections.fit_of`), in the world frame (the hole
frame of a mesh task is the world's, moved to the entry: :mod:`teachfit.tasks.mesh.cell`).
A round hole (its vertices within :data:`ROUND_TOL` of one radius) is labelled with its
diameter, any other with its width and height along the hole frame's x and y. Lengths in m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.cell import MeshCell
from teachfit.tasks.mesh.sections import ENTRY_EPS, section

#: most a round hole's vertex radii may spread, as a fraction of their largest
ROUND_TOL = 0.01


@dataclass(frozen=True)
class HoleOutline:
    """The hole's outline ``xy`` (n, 2; world, m, closed), whether it is ``round``, and its
    ``size``: the diameter twice (round) or the width and height (m)."""

    xy: np.ndarray
    round: bool
    size: tuple[float, float]

    def label(self) -> str:
        """``"hole, Ø 8.20 mm"`` or ``"hole, 12.40 x 4.90 mm"``."""
        if self.round:
            return f"hole, Ø {1e3 * self.size[0]:.2f} mm"
        return f"hole, {1e3 * self.size[0]:.2f} x {1e3 * self.size[1]:.2f} mm"


def walls_down_to(cell: MeshCell, depth: float) -> BaseGeometry:
    """Union of the fixed part's sections (hole frame, m) from just below the entry down to
    ``depth`` (m), every 0.5 mm."""
    fixed_h = cell.fixed.copy()
    fixed_h.apply_translation(-cell.hole2world.pos)
    zs = -np.linspace(ENTRY_EPS, depth, max(4, int(np.ceil(depth / 5e-4)) + 1))
    return shapely.unary_union([section(fixed_h, float(z)) for z in zs])


def hole_outline(cell: MeshCell) -> HoleOutline:
    """The :class:`HoleOutline` of ``cell`` (see the module docstring)."""
    walls = walls_down_to(cell, cell.success_depth)
    axis = shapely.Point(0.0, 0.0)
    for poly in getattr(walls, "geoms", [walls]):
        for ring in getattr(poly, "interiors", []):
            if shapely.Polygon(ring).contains(axis):
                xy = np.asarray(ring.coords)[:, :2]
                return _outline_of(xy, cell.hole2world.pos[:2])
    raise TaskError(f"{cell.spec.path}: no opening around the hole axis down to the success depth")


def _outline_of(xy: np.ndarray, origin: np.ndarray) -> HoleOutline:
    """The outline of the ring ``xy`` (hole frame, m) moved to ``origin`` (world, m)."""
    centre = np.asarray(shapely.Polygon(xy).centroid.coords[0])
    r = np.linalg.norm(xy - centre, axis=1)
    if r.max() - r.min() <= ROUND_TOL * r.max():
        d = 2 * float(r.max())
        return HoleOutline(xy + origin, True, (d, d))
    w, h = np.ptp(xy, axis=0)
    return HoleOutline(xy + origin, False, (float(w), float(h)))
