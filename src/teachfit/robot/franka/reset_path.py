"""A reset path that never drags the part sideways out of a hole: out along the axis first.

Between two trials on a real arm the part may sit inside the hole (a success) or pressed into
its edge (a failure). A straight line from there to the next start would move it sideways
while it is still engaged: it levers on the hole's wall, loads the fixture and the grasp, and
can pull the part out of the fingers. The reset therefore goes through via points in the hole
frame ``H`` (origin at the entry centre, z out of the hole):

0. **release** (when the TCP starts below the clearance plane): the skill's press is let go
   at once; a part the skill left still sliding into the hole (up to 0.2 m/s on the peg
   twin) is braked along the hole's axis alone, then held where it stopped, soft along the
   axis (``release_stiffness``) and compliant across it and about every axis
   (:func:`leave_stiffness`), until the TCP is at rest. The brake's set-point follows a
   smooth stop (:func:`brake_profile`: no step in the force, at most ``brake_decel``), with
   the arm's operational-space inertia times that deceleration as the feed-forward
   (:func:`release_command`): a force along the axis alone would also accelerate the arm
   across it (the inertia's off-diagonal terms; on the peg twin 1 N along the axis
   accelerates the TCP 0.29 m/s² across it and 0.23 m/s² along it), and the hole's wall
   would take that up. Braked by the impedance alone the part pressed 4-14 N on the wall,
   or reached the hole's bottom still moving and pressed 7-11 N on it;
1. **out**: from where the release settled straight along the hole's z to ``clear_height``
   above the entry, keeping x, y and the orientation (a pure motion along the insertion
   axis), with the same compliance across the axis, so the hole guides the part;
2. **over**: at that height to above the next start, turning to its orientation there;
3. **down** to the start, if the start lies below the clearance plane.

A TCP already above the clearance plane goes straight to the start. While the part leaves
the hole, the lateral force it sees is watched (:class:`ResetGuard`): every reset's peak is
recorded, and one beyond ``abort_force`` stops the reset before it pulls harder. The start of
the release reads the force the *skill* left, fading out of libfranka's filtered estimate
(on the peg twin a 13 N press let go still reads 8 N after 20 ms, 3 N after 30 ms); the
first reading after the hand-over (the estimate lags) and those that keep falling from it,
within ``handover_time``, are kept apart as the hand-over peak. (On the peg twin every
hand-over peak over 5 N was, within 0.4 N, the reading taken before the reset's first
command: the skill's own force at the end of its execution.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from teachfit.core.errors import NeedsAPerson, TeachfitError
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand

#: s over which the brake's deceleration rises and falls (:func:`brake_profile`)
BRAKE_RAMP = 0.01


@dataclass(frozen=True)
class ResetCell:
    """The hole a reset must leave along its axis.

    ``hole2world`` the hole frame (world); ``clear_height`` (m) the height above the entry,
    along the hole's z, from which the TCP (the part's tip) is clear of the fixture;
    ``abort_force`` (N) the lateral force in the hole frame at which the way out stops;
    ``leave_stiffness`` (N/m across the hole's axis, N·m/rad about every axis) of the release
    and the way out (:func:`leave_stiffness`); ``release_time`` (s of robot time) the least
    and the most the release holds before the way out starts (the least lets the wrench
    estimate's filters catch up with the let-go press); ``release_stiffness`` (N/m) along
    the hole's axis during the release; ``handover_time`` (s) from the release's start within
    which a falling reading is the skill's force fading, not the reset's (:class:`ResetGuard`);
    ``brake_decel`` (m/s²) the largest deceleration along the axis that stops a part still
    sliding at the hand-over (:func:`brake_profile`).
    """

    hole2world: Pose
    clear_height: float
    abort_force: float = 15.0
    leave_stiffness: tuple[float, float] = (200.0, 10.0)
    release_time: tuple[float, float] = (0.05, 0.5)
    release_stiffness: float = 300.0
    handover_time: float = 0.05
    brake_decel: float = 8.0

    def __post_init__(self) -> None:
        lo, hi = self.release_time
        soft = (*self.leave_stiffness, self.release_stiffness, self.brake_decel)
        if min(soft) <= 0 or not 0 <= lo <= hi or not 0 <= self.handover_time <= lo:
            raise TeachfitError(
                f"reset cell: leave_stiffness {self.leave_stiffness}, release_stiffness "
                f"{self.release_stiffness} and brake_decel {self.brake_decel} must be > 0, "
                f"release_time {self.release_time} a (least, most) pair >= 0 s, handover_time "
                f"{self.handover_time} s in [0, least]"
            )


def leave_stiffness(cell: ResetCell, along: float) -> np.ndarray:
    """The (6, 6) stiffness (world axes; N/m, N·m/rad) of the release and the way out:
    ``along`` N/m along the hole's z, ``cell.leave_stiffness`` across it and about every axis.

    At the reset's own stiffness across the axis (2000 N/m, 100 N·m/rad) an arm that holds a
    tilted part still sliding into the hole, or pressed on a wall, levers it there: 5-13 N
    lateral on the peg twin. Compliant across the axis the walls, not the arm, set where the
    part goes, and the lateral force stays that of the arm's small disturbances."""
    across, turn = cell.leave_stiffness
    rot = cell.hole2world.rotation.as_matrix()
    k = np.zeros((6, 6))
    k[:3, :3] = rot @ np.diag([across, across, float(along)]) @ rot.T
    k[3:, 3:] = np.eye(3) * turn
    return k


def brake_time(speed: float, decel: float, ramp: float = BRAKE_RAMP) -> float:
    """How long (s) :func:`brake_profile` takes to stop ``speed`` (m/s) at most ``decel``
    (m/s²), its deceleration rising and falling over ``ramp`` (s)."""
    if speed == 0.0:
        return 0.0
    peak = min(decel, abs(speed) / ramp)
    return abs(speed) / peak + ramp


def brake_profile(
    speed: float, decel: float, t: float, ramp: float = BRAKE_RAMP
) -> tuple[float, float, float]:
    """Distance (m), speed (m/s) and acceleration (m/s²) along an axis ``t`` s into a stop from
    ``speed`` (m/s, signed along the axis) at most ``decel`` (m/s²).

    The deceleration rises linearly to its peak ``a = min(decel, |speed| / ramp)`` over
    ``ramp`` s, holds, and falls back to zero over the last ``ramp`` s (a jerk of at most
    ``decel / ramp``: no step in the force at the hand-over, nor in the joint torques' rate), so
    the stop takes ``T = |speed| / a + ramp`` (:func:`brake_time`) and covers ``speed T / 2``:
    ``speed² / 2a + speed ramp / 2``, the shortest at that jerk and deceleration. After ``T``:
    at rest there."""
    big_t = brake_time(speed, decel, ramp)
    if big_t <= 0.0:
        return 0.0, 0.0, 0.0
    sign, peak = float(np.sign(speed)), min(decel, abs(speed) / ramp)
    jerk = peak / ramp
    hold = big_t - 2.0 * ramp  # >= 0 s at the peak deceleration

    def rising(s: float) -> tuple[float, float, float]:  # s in [0, ramp]: a = -jerk s
        return abs(speed) * s - jerk * s**3 / 6.0, abs(speed) - jerk * s * s / 2.0, -jerk * s

    t = min(max(t, 0.0), big_t)
    if t <= ramp:
        dist, vel, acc = rising(t)
    else:
        d1, v1, _ = rising(ramp)
        s = min(t - ramp, hold)
        dist, vel, acc = d1 + v1 * s - peak * s * s / 2.0, v1 - peak * s, -peak
        if t > ramp + hold:  # falling: a = -peak + jerk s
            s = t - ramp - hold
            dist += vel * s - peak * s * s / 2.0 + jerk * s**3 / 6.0
            vel += -peak * s + jerk * s * s / 2.0
            acc = -peak + jerk * s
    if t >= big_t:
        vel, acc = 0.0, 0.0
    return sign * dist, sign * vel, sign * acc


def release_command(
    cell: ResetCell, start: Pose, speed: float, inertia: np.ndarray, decel: float, t: float
) -> ImpedanceCommand:
    """The release's command ``t`` s after the hand-over at ``start`` (world TCP pose) of a
    part moving at ``speed`` (m/s along the hole's z), braked at most at ``decel`` (m/s²).

    The set-point follows :func:`brake_profile` along the hole's z from ``start`` (x, y and the
    orientation kept), at the release's stiffness (:func:`leave_stiffness`); the feed-forward
    ``inertia @ [a; 0]`` (``inertia`` the TCP's operational-space inertia (6, 6), world;
    ``a`` the profile's acceleration along the axis) brakes along the axis alone."""
    axis = cell.hole2world.rotation.apply([0.0, 0.0, 1.0])
    dist, vel, acc = brake_profile(speed, decel, t)
    return ImpedanceCommand(
        pos=start.pos + dist * axis,
        quat=start.quat,
        lin_vel=vel * axis,
        wrench_ff=np.asarray(inertia, dtype=float)[:, :3] @ (acc * axis),
        stiffness=leave_stiffness(cell, cell.release_stiffness),
        expires_after=1.0,
    )


def brake_decel(cell: ResetCell, inertia: np.ndarray, max_force: float, max_torque: float) -> float:
    """The deceleration (m/s²) the release brakes at: ``cell.brake_decel``, less where its
    feed-forward (:func:`release_command`) would pass 80 % of ``max_force`` (N) or
    ``max_torque`` (N·m), which the driver refuses."""
    axis = cell.hole2world.rotation.apply([0.0, 0.0, 1.0])
    per = np.asarray(inertia, dtype=float)[:, :3] @ axis  # wrench per m/s² along the axis
    decel = cell.brake_decel
    for part, cap in ((slice(0, 3), max_force), (slice(3, 6), max_torque)):
        need = float(np.linalg.norm(per[part]))
        if need * decel > 0.8 * cap:
            decel = 0.8 * cap / need
    return decel


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

    :meth:`take_over` takes the reading at the hand-over (before the reset's first command:
    the skill's force), :meth:`watch` each measured wrench (world frame, force first) of the
    release and the ``out`` leg. A reading within the release's first ``handover_time``
    (``handover``) belongs to the hand-over if it is the first after the take-over (the
    estimate lags 10-20 ms: it still shows the skill's force, rising if that was rising) or
    falls from the one before (the skill's force fading out of the filtered estimate). The
    first that does neither ends the hand-over; it and every later one are the reset's own.
    ``peak`` is the largest lateral force of the reset's own, ``handover`` the hand-over's;
    ``peaks`` and ``handover_peaks`` keep every finished reset's. A reading of the reset's
    own past ``abort_force`` raises :class:`~teachfit.core.errors.NeedsAPerson` (the skill's
    force is let go at the take-over: a part caught in the hole pulls when the reset moves).
    """

    cell: ResetCell
    peak: float = 0.0
    handover: float = 0.0
    peaks: list[float] = field(default_factory=list)
    handover_peaks: list[float] = field(default_factory=list)
    _fading: float | None = field(default=None, repr=False)  # the hand-over's last reading
    _first: bool = field(default=False, repr=False)  # no reading watched since the take-over

    def lateral(self, wrench_world: np.ndarray) -> float:
        """The lateral force (N) of ``wrench_world`` (6,) (world, force first)."""
        f_hole = self.cell.hole2world.inverse().rotation.apply(np.asarray(wrench_world)[:3])
        return float(np.hypot(f_hole[0], f_hole[1]))

    def take_over(self, wrench_world: np.ndarray) -> None:
        """Start the hand-over at the reading before the reset's first command."""
        self._fading = self.lateral(wrench_world)
        self._first = True
        self.handover = max(self.handover, self._fading)

    def watch(self, wrench_world: np.ndarray, handover: bool = False) -> None:
        """Record the lateral force of ``wrench_world``: in the hand-over's peak if
        ``handover`` (within the release's first ``handover_time``) and it is the first
        reading after the take-over or below the one before, else in the reset's own; raise
        :class:`NeedsAPerson` when the reset's own passes ``abort_force``."""
        lateral = self.lateral(wrench_world)
        fading = self._fading is not None and (self._first or lateral < self._fading)
        self._first = False
        if handover and fading:
            self._fading = lateral
            self.handover = max(self.handover, lateral)
            return
        self._fading = None
        self.peak = max(self.peak, lateral)
        if lateral > self.cell.abort_force:
            self.finish()
            raise NeedsAPerson(
                f"reset stopped leaving the hole: {lateral:.1f} N lateral force (limit "
                f"{self.cell.abort_force:.0f} N); the part is caught in the hole: free it by hand, "
                "then run again"
            )

    def finish(self) -> float:
        """Close the current reset: keep its peaks, start the next at zero; the peak (N)."""
        peak, self.peak = self.peak, 0.0
        self.peaks.append(peak)
        self.handover_peaks.append(self.handover)
        self.handover, self._fading, self._first = 0.0, None, False
        return peak
