"""Checks shared by the round-peg cells (``peg2d``, ``peg``): a chamfered peg, a ring hole.

Both cells' parameters have ``peg_diameter``, ``peg_chamfer``, ``peg_length``, ``clearance``,
``hole_depth``, ``success_depth`` and ``n_sectors`` (lengths in metres).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from teachfit.tasks.params import TaskParams


class _RoundPeg(Protocol):
    """The fields a round-peg cell's parameters have (m; ``n_sectors`` a count)."""

    @property
    def peg_diameter(self) -> float: ...
    @property
    def peg_chamfer(self) -> float: ...
    @property
    def peg_length(self) -> float: ...
    @property
    def hole_depth(self) -> float: ...
    @property
    def success_depth(self) -> float: ...
    @property
    def n_sectors(self) -> int: ...
    def require(self, condition: bool, message: str) -> None: ...
    def require_reachable(self, success_depth: float, depth: float, hole: str) -> None: ...


@dataclass(frozen=True)
class RoundPegParams(TaskParams):
    """Mixin without fields: :meth:`check_round_peg` for the round-peg cells' parameters."""

    def check_round_peg(self: _RoundPeg) -> None:
        """The peg fits its hole, reaches the success depth and stands out of the hole."""
        self.require(
            self.peg_chamfer < self.peg_diameter / 2,
            "peg_chamfer must be smaller than the peg radius",
        )
        self.require_reachable(self.success_depth, self.hole_depth, "hole")
        self.require(self.peg_length > self.hole_depth, "peg_length must exceed hole_depth")
        self.require(8 <= self.n_sectors <= 256, "n_sectors must be within [8, 256]")
