"""``socket3d``: a two-pin plug into a recessed round socket with valleys (Ehlers et al. 2019, 3D).

Europlug-like plug: two round pins (``pin_diameter``, ``pin_spacing`` apart, rounded tips) under
a round plug body. Socket: a round recess (``recess_diameter`` x ``recess_depth``) whose wall
keeps the plug body inside it; its floor (flat top at ``floor_height``, world z) holds two holes
on the world x-axis at ``x = -pin_spacing / 2`` (the *small* hole, ``clearance_small``) and
``x = +pin_spacing / 2`` (the *large* hole, ``clearance_large``), both diametral clearances.
Each hole sits at the bottom of a valley: a faceted funnel falling ``valley_depth`` from the
floor at ``valley_radius`` to the hole edge, which guides a compliantly pushed pin into the
hole. The socket centre is at the world origin in x-y (:mod:`teachfit.tasks.scene.socket`).

Frames. The TCP is the midpoint of the two pin tips, the plug's +z axis up; at ``rz = 0`` the
pins lie along the world x-axis, matching the holes. The hole frame (:attr:`hole2world`) is the
midpoint between the holes at the height of the hole entries (the valley bottoms, i.e.
``floor_height - valley_depth``; the floor itself when ``valley_depth = 0``), z up, so
:meth:`insertion_depth` is how deep the pins are in their holes. The plug is two-fold
symmetric: ``rz = pi`` inserts as well (each pin then enters the other hole; the pins are equal,
so :meth:`ground_truth_inserted` accepts both). The search is in x, y and rz.

The holes are shallower than the pins reach, so a fully inserted plug stands on its pin tips
and its body never seats on the ~40 floor pieces (which would cost ~100 contacts per step).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.tasks.base import Task
from teachfit.tasks.geometry.socket3d_params import Socket3DParams
from teachfit.tasks.protocols.ehlers import SocketProtocol
from teachfit.tasks.scene.socket import SocketScene

__all__ = ["Socket3D", "Socket3DParams"]


class Socket3D(Task):
    """Two-pin plug into a recessed socket with valleys; search in x, y and rz."""

    name = "socket3d"
    description = (
        "two-pin plug into a recessed socket with valleys; search x-y-rz "
        "(Ehlers et al. 2019, Table III)"
    )
    search_dims = ("x", "y", "rz")
    params_type = Socket3DParams
    scene_type = SocketScene
    protocol_type = SocketProtocol
    params: Socket3DParams
    protocol: SocketProtocol
    #: the plug is two-fold symmetric: it inserts at rz and at rz + pi (rad)
    rz_period: ClassVar[float] = float(np.pi)

    @property
    def surface_z(self) -> float:
        return self.params.floor_height

    @property
    def hole2world(self) -> Pose:
        return Pose(np.array([0.0, 0.0, self.params.floor_height - self.params.valley_depth]))

    @property
    def capture_radius(self) -> float:
        return self.params.clearance_large + 1e-4

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

    @property
    def detection_radius(self) -> float:
        """Within :attr:`play` of the socket axis the plug is inside the recess."""
        return self.play

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
