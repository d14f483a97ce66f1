"""Ehlers et al.'s start protocols: ``peg2d`` (tables 1 and 2) and ``socket3d`` (table 3).

Poses are TCP poses in the world frame resting on the task's surface
(:meth:`~teachfit.tasks.base.Task.contact_pose`); lengths in metres, angles in radians.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.tasks.protocols.base import Protocol

if TYPE_CHECKING:
    from teachfit.tasks.geometry.peg2d import Peg2D
    from teachfit.tasks.geometry.socket3d import Socket3D

#: radius of the circle table 1's starts are drawn in (m): 3 cm diameter
TABLE1_RADIUS = 0.015


class Peg2DProtocol(Protocol):
    """Ehlers et al.'s 2D protocols on the cylinder top."""

    task: Peg2D
    names = ("table1", "table2")

    def teacher_start(self, rng: np.random.Generator) -> Pose:
        """On the surface ``demo_offset`` from the hole axis in a uniform random direction."""
        ang = rng.uniform(0, 2 * np.pi)
        return self.task.contact_pose(
            self.task.params.demo_offset * np.array([np.cos(ang), np.sin(ang)])
        )

    def paper_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None
    ) -> list[Pose]:
        """``"table1"``: ``n`` starts uniform in a 3 cm-diameter circle centred halfway between
        the demonstration's start (default: ``demo_offset`` along +x) and the hole.
        ``"table2"``: ``n`` copies of that centre."""
        task = self.task
        if demo_start is None:
            demo_start = task.contact_pose(np.array([task.params.demo_offset, 0.0]))
        centre = (demo_start.pos[:2] + task.hole2world.pos[:2]) / 2
        if protocol == "table2":
            return [task.contact_pose(centre)] * n
        r = TABLE1_RADIUS * np.sqrt(rng.uniform(0, 1, n))
        a = rng.uniform(0, 2 * np.pi, n)
        return [
            task.contact_pose(centre + ri * np.array([np.cos(ai), np.sin(ai)]))
            for ri, ai in zip(r, a, strict=True)
        ]


class SocketProtocol(Protocol):
    """Ehlers et al.'s 3D protocol inside the socket's recess."""

    task: Socket3D
    names = ("table3",)

    def in_valley(self, pose: Pose) -> bool:
        """Whether a pin tip starts inside a valley (it would be guided in at once)."""
        tips = self.task.pin_tips(pose)[:, :2]
        holes = self.task.hole_xy
        dist = np.linalg.norm(tips[:, None, :] - holes[None, :, :], axis=2)
        return bool(np.any(dist < self.task.params.valley_radius))

    def teacher_start(self, rng: np.random.Generator) -> Pose:
        """Plug inside the recess, ``start_wall_gap`` from the wall, in the upper half (y >= 0).

        The direction from the socket centre is uniform over the upper half, rz uniform within
        ``+-start_rz``; draws whose pins start inside a valley are redrawn (up to 100 times).
        The pins rest on the floor (TCP at ``surface_z``).
        """
        task = self.task
        dist = task.play - task.params.start_wall_gap
        pose = task.contact_pose(np.zeros(2))
        for _ in range(100):
            ang = rng.uniform(0.0, np.pi)
            rz = rng.uniform(-task.params.start_rz, task.params.start_rz)
            pose = task.contact_pose(dist * np.array([np.cos(ang), np.sin(ang)]), rz)
            if not self.in_valley(pose):
                break
        return pose

    def paper_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None
    ) -> list[Pose]:
        """``"table3"``: ``n`` starts (the paper used 15) uniform over the socket's upper half:
        the plug centre uniform in the half disc ``y > 0`` of radius ``play`` minus 0.5 mm (the
        body never touches the wall), rz uniform within ``+-start_rz``. ``demo_start`` is not
        used."""
        del protocol, demo_start
        task = self.task
        r = (task.play - 0.0005) * np.sqrt(rng.uniform(0.0, 1.0, n))
        a = rng.uniform(0.0, np.pi, n)
        rz = rng.uniform(-task.params.start_rz, task.params.start_rz, n)
        return [
            task.contact_pose(ri * np.array([np.cos(ai), np.sin(ai)]), zi)
            for ri, ai, zi in zip(r, a, rz, strict=True)
        ]
