"""A reset path that never drags the part sideways out of a hole: out along the axis first.

Between two trials on a real arm the part may sit inside the hole (a success) or pressed into
its edge (a failure). A straight line from there to the next start would move it sideways
while it is still engaged: it levers on the hole's wall, loads the fixture and the grasp, and
can pull the part out of the fingers. The reset therefore goes through via points in the hole
frame ``H`` (origin at the entry centre, z out of the hole):

1. **out**: from the current TCP straight along the hole's z to ``clear_height`` above the
   entry, keeping x, y and the orientation (a pure motion along the insertion axis);
2. **over**: at that height to above the next start, turning to its orientation there;
3. **down** to the start, if the start lies below the clearance plane.

A TCP already above the clearance plane goes straight to the start. While the part leaves
the hole, the lateral force it sees is watched (:class:`ResetGuard`): every reset's peak is
recorded, and one beyond ``abort_force`` stops the reset before it pulls harder.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from teachfit.core.errors import NeedsAPerson
from teachfit.core.geometry import Pose


@dataclass(frozen=True)
class ResetCell:
    """The hole a reset must leave along its axis.

    ``hole2world`` the hole frame (world); ``clear_height`` (m) the height above the entry,
    along the hole's z, from which the TCP (the part's tip) is clear of the fixture;
    ``abort_force`` (N) the lateral force in the hole frame at which the way out stops.
    """

    hole2world: Pose
    clear_height: float
    abort_force: float = 15.0


def reset_via_points(current: Pose, goal: Pose, cell: ResetCell | None) -> list[tuple[str, Pose]]:
    """The legs of a reset from ``current`` to ``goal`` (world TCP poses), as
    ``(name, end pose)``: ``out``, ``over``, ``down`` as in the module docstring, or one
    ``direct`` leg when no cell is given or the TCP is already clear."""
    if cell is None:
        return [("direct", goal)]
    world2hole = cell.hole2world.inverse()
    here, there = world2hole.compose(current), world2hole.compose(goal)
    h = cell.clear_height
    if here.pos[2] >= h:
        return [("direct", goal)]
    out = cell.hole2world.compose(Pose(np.array([here.pos[0], here.pos[1], h]), here.quat))
    legs = [("out", out)]
    if there.pos[2] >= h:
        return [*legs, ("over", goal)]
    over = cell.hole2world.compose(Pose(np.array([there.pos[0], there.pos[1], h]), there.quat))
    return [*legs, ("over", over), ("down", goal)]


@dataclass
class ResetGuard:
    """Watches the lateral force (N, hole frame x-y) while a reset leaves the hole.

    :meth:`watch` takes each measured wrench (world frame, force first) of the ``out`` leg;
    ``peak`` is the largest lateral force seen; ``peaks`` keeps every finished reset's. Past
    ``abort_force`` it raises :class:`~teachfit.core.errors.NeedsAPerson`.
    """

    cell: ResetCell
    peak: float = 0.0
    peaks: list[float] = field(default_factory=list)

    def watch(self, wrench_world: np.ndarray) -> None:
        """Record the lateral force of ``wrench_world``; raise :class:`NeedsAPerson` past
        ``abort_force``."""
        f_hole = self.cell.hole2world.inverse().rotation.apply(np.asarray(wrench_world)[:3])
        lateral = float(np.hypot(f_hole[0], f_hole[1]))
        self.peak = max(self.peak, lateral)
        if lateral > self.cell.abort_force:
            self.finish()
            raise NeedsAPerson(
                f"reset stopped leaving the hole: {lateral:.1f} N lateral force (limit "
                f"{self.cell.abort_force:.0f} N); the part is caught in the hole: free it by hand, "
                "then run again"
            )

    def finish(self) -> float:
        """Close the current reset: keep its peak, start the next at zero; the peak (N)."""
        peak, self.peak = self.peak, 0.0
        self.peaks.append(peak)
        return peak
