"""What a task's experiment protocols provide: search poses and the papers' start poses.

A :class:`Protocol` reads the task's geometry (:class:`~teachfit.tasks.base.Task`): world z up,
the hole frame at the entry centre, the TCP the lowest point of the held part on its axis.
Every protocol has the ``"teacher"`` starts (worst-case starts of a blind demonstration) and
the paper protocols named in :attr:`Protocol.names`; all draws come from the caller's seeded
generator.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose

if TYPE_CHECKING:
    from teachfit.tasks.base import Task


@dataclass(frozen=True)
class Protocol(ABC):
    """Start poses and search poses of one task; ``task`` gives the geometry (m, rad)."""

    task: Task
    #: the paper protocols besides ``"teacher"``, e.g. ("table1", "table2")
    names: ClassVar[tuple[str, ...]]

    def search_pose(self, state: np.ndarray, search2world: Pose, height: float = 0.0) -> Pose:
        """Tool pose for a search state (the task's ``search_dims``: x, y in m, rz in rad)
        given in the search frame ``search2world``, ``height`` (m) above it."""
        s = np.asarray(state, dtype=float)
        dims = self.task.search_dims
        if s.shape != (len(dims),):
            raise TaskError(
                f"{self.task.name} search states are ({', '.join(dims)}), got shape {s.shape}"
            )
        rz = float(s[dims.index("rz")]) if "rz" in dims else 0.0
        return search2world.compose(Pose.from_xyz_rz(s[0], s[1], height, rz))

    @abstractmethod
    def teacher_start(self, rng: np.random.Generator) -> Pose:
        """A worst-case start for a blind demonstration (on the surface, off the hole)."""

    def protocol_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None = None
    ) -> list[Pose]:
        """``n`` start poses (world) of ``protocol``: ``"teacher"`` or one of :attr:`names`.

        ``demo_start`` is the demonstration's start where a protocol is defined relative to
        it (see the subclass's :meth:`paper_starts`).
        """
        if n <= 0:
            raise TaskError(f"number of starts must be positive, got {n}")
        if protocol == "teacher":
            return [self.teacher_start(rng) for _ in range(n)]
        if protocol not in self.names:
            known = ", ".join((*self.names, "teacher"))
            raise TaskError(f"{self.task.name} has protocols {known}; not {protocol!r}")
        return self.paper_starts(protocol, n, rng, demo_start)

    @abstractmethod
    def paper_starts(
        self, protocol: str, n: int, rng: np.random.Generator, demo_start: Pose | None
    ) -> list[Pose]:
        """``n > 0`` starts of the paper protocol ``protocol`` (one of :attr:`names`)."""
