"""Searching with a tilted part: tilt, feel the drop, slide to the wall, align (seed B's
``tilt``, ``lateral`` and ``align`` primitives inside a search follower).

An upright sharp-edged peg drops into its hole only when its axis passes within the radial
clearance of the hole's (0.1-0.25 mm in the peg2d variants). Tilted by ``angle`` about the
horizontal axis z x d, its lowest point is one rim point, ``d`` (a fixed task-frame direction:
by default from the trajectory's start toward its centroid, the part leaning toward where it
searches) from the axis; that point drops as soon as it is over the hole, deep enough to
feel near the hole's line along ``d`` (millimetres, not tenths; see *Lead* below).
:class:`TiltState` then runs these phases:

1. *search*: the follower's set-points, the orientation tilted; the reference height is the
   highest the TCP has been since the tilt settled (the tilted part rests one
   ``r sin(angle)`` above the surface); while it settles after a missed align, never below
   the height the part stood upright at on the edge (tilted again right over the hole, it
   drops in before it settles);
2. *lateral*: once the TCP sank ``drop_depth`` below it, the x-y set-point moves from the
   TCP along ``d`` at ``lateral_speed``: the low rim slides across the hole until its far
   wall stops it (the set-point then leads the TCP by ``stall_lag``), or the TCP has gone
   ``lateral_reach`` (the hole's diameter); back up within half ``drop_depth`` of the
   reference height, the rim rode out over the edge: the search goes on. Across ``d`` the
   part is free (*Free across*);
3. *align*: x-y held where the TCP is (the follower's soft hold stiffness), the tilt goes to
   zero linearly over ``align_time`` while the push goes on: turning about the rim that
   rests on the far wall, the part swings over the hole and slides in. Upright and not
   sinking ``RETRY`` s later, it missed (it stands on the edge): the search goes on, tilted,
   from where the trajectory was left (:class:`~teachfit.skills.follow.FollowSetpoints`
   pauses the trajectory's clock outside the search phase and blends back to it);
4. *lift*: a drop in the lateral phase deeper than ``off_depth`` (a tilted part enters a
   hole far less deep than the hole is) was the part leaving the top over its outer edge,
   the low rim first (Ø 30 mm, 0.5 mm, μ 0.5: a 58 mm "drop" 46 mm from the hole on a Ø 120
   mm top: the low rim went over the edge, the part pivoted on it and slid down the block's
   side for the whole reach, and then stood on the floor beside the block, pushed there,
   until the time ran out). Without the push, the set-point rises until the TCP is
   ``LIFT_CLEAR`` / 2 above the top's height, then moves at ``LIFT_SPEED`` back over the top
   to where the trajectory was left, and the search goes on from there upright (upright,
   a part whose axis is over the top stays on it) until the TCP is ``lateral_reach`` from
   where the drop was felt; then tilted again (tilted there again, the low rim went over the
   same edge again: the same fall, lift and return, over and over).

Lead. The point that feels the hole is the low rim, ``r cos(angle)`` ahead of the axis along
``d``; a trajectory planned for where the hole may be is planned for that point, so the
follower moves its set-points back by ``lead`` along ``d`` (:func:`rim_lead`; ramped in over
``LEAD_TIME`` at the start). Without it the rim swept the planned region shifted a radius
ahead, and a wide part's tour passed with the rim 10-14 mm from the hole's centre (Ø 30 mm,
0.5 mm, μ 0.5, 5 of 20 starts): the part sinks deep enough to feel only where the rim is
near the hole's line along ``d`` (offset across it, its neighbours on the rim rest on the top
beside the hole and it sinks a fraction of a millimetre).

Free across. A drop is felt with the low rim up to a few millimetres beside the hole's line
along ``d`` (Ø 30 mm, 0.5 mm, μ 0.5: 5-9 mm on the starts that failed). Held there by the
across-stiffness, the rim slid along that chord and rode out short of the far wall. In the
lateral phase the set-point across ``d`` is where the TCP is, so the hole's curved wall,
pushing the rim along its normal, centres it on the line, as a hand sliding a tilted peg
relaxes sideways (that variant: 17/20 -> 18/20 starts; BENCHMARKS.md).

Jams. A wide part that dropped in deep at a large tilt can jam while it turns upright: its
high rim comes down on the top beside the near edge while its side still rests on the far
edge, and from there pushing only wedges it or walks it back out (Ø 30 mm, 0.3 mm clearance,
μ 0.8 at 0.25 rad: the same drop, turn and miss for two minutes). Turning a part of radius
``r`` upright about the far edge of a hole of radius ``R``, the high rim clears the near
edge for any depth once the tilt is at most ``acos(r / R)`` (0.14 rad there). A small tilt
costs elsewhere (the part tends to end upright beside the axis: Ø 30 mm, 0.2 mm, μ 0.5 at
0.115 rad succeeds 11/20 against 20/20 at 0.25 rad), so the search keeps ``angle`` and after
each missed align alternates with ``retry_angle`` (None: ``angle`` always), as a hand that
felt a jam tries again more upright.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teachfit.core.errors import SkillError
from teachfit.core.geometry import quat_mul_into
from teachfit.skills.percept import Percept

#: time (s) the lateral phase waits at its full reach before aligning anyway
SETTLE = 0.5
#: time (s) after the search (re)starts before a drop can be felt: the part is still tilting
#: and bounces up by more than a drop (a Ø 20 mm peg rises 2.5 mm, overshooting by 0.7 mm)
TILT_SETTLE = 0.3
#: a part upright for ``RETRY`` s (s) that sank less than ``RETRY_SINK`` (m) since is on the
#: edge, not in the hole: the search goes on (an inserting part slides in within 0.3 s)
RETRY, RETRY_SINK = 0.5, 0.001
#: height (m) above the top's resting height that a part which left the top is lifted
#: to, at least half of it, before it moves back over the top (its low rim clears the edge)
LIFT_CLEAR = 0.002
#: speed (m/s) of the lift's set-point, going up and then back over the top
LIFT_SPEED = 0.05
#: time (s) over which a search with a ``lead`` moves its set-point back by it at the start
LEAD_TIME = 0.5
#: phases of a tilted search
SEARCH, LATERAL, ALIGN, LIFT = 0, 1, 2, 3


@dataclass(frozen=True)
class TiltConfig:
    """A tilted search (rad, m, m/s, s): see the module docstring."""

    angle: float = 0.15
    direction: float | None = None
    drop_depth: float = 5e-4
    lateral_reach: float = 0.02
    lateral_speed: float = 0.005
    stall_lag: float = 0.003
    align_time: float = 0.5
    retry_angle: float | None = None
    off_depth: float | None = None
    lead: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.angle) and 0.0 < self.angle < 0.6):
            raise SkillError(f"tilt: angle must be in (0, 0.6) rad, got {self.angle}")
        if self.retry_angle is not None and not (
            math.isfinite(self.retry_angle) and 0.0 < self.retry_angle < 0.6
        ):
            raise SkillError(f"tilt: retry_angle must be in (0, 0.6) rad, got {self.retry_angle}")
        if self.off_depth is not None and not (
            math.isfinite(self.off_depth) and self.off_depth > self.drop_depth
        ):
            raise SkillError(
                f"tilt: off_depth must exceed drop_depth ({self.drop_depth}), got {self.off_depth}"
            )
        if not (math.isfinite(self.lead) and self.lead >= 0.0):
            raise SkillError(f"tilt: lead must be >= 0 m, got {self.lead}")
        if self.direction is not None and not math.isfinite(self.direction):
            raise SkillError(f"tilt: direction must be finite, got {self.direction}")
        for name in ("drop_depth", "lateral_reach", "lateral_speed", "stall_lag", "align_time"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise SkillError(f"tilt: {name} must be > 0, got {value}")

    @property
    def extra_time(self) -> float:
        """The longest the lateral and align phases take (s): a drop at the trajectory's end
        still gets them before the time budget runs out."""
        return self.lateral_time + self.align_time

    @property
    def lateral_time(self) -> float:
        """The longest lateral phase (s): the reach and the stall lead at its speed."""
        return (self.lateral_reach + self.stall_lag) / self.lateral_speed + SETTLE

    def unit(self, path: np.ndarray) -> np.ndarray:
        """The tilt direction ``d`` (2,), task frame: the low rim's side; without a
        ``direction``, from the first of the ``path`` points (N, >= 2; m) to their centroid
        (+x if they are all one point)."""
        if self.direction is not None:
            return np.array([math.cos(self.direction), math.sin(self.direction)])
        pts = np.asarray(path, dtype=float)[:, :2]
        v = pts.mean(axis=0) - pts[0]
        n = float(np.hypot(v[0], v[1]))
        return v / n if n > 1e-9 else np.array([1.0, 0.0])


def rim_lead(angle: float, diameter: float) -> float:
    """How far (m) the lowest point of a cylinder of ``diameter`` (m) tilted by ``angle``
    (rad) is ahead of its axis, horizontally: ``D cos(angle) / 2``."""
    return 0.5 * diameter * math.cos(angle)


def tilted_drop(angle: float, diameter: float, clearance: float) -> float:
    """The deepest (m) the low rim of a cylinder of ``diameter`` (m) tilted by ``angle``
    (rad) gets below a flat top into a sharp-edged round hole ``clearance`` (m, diametral)
    wider: with its high rim still on the top, ``D sin(angle)``; with both rims inside, as
    deep as the low side of its body, leaning on over the far wall, lets it:
    ``(D + c - D cos(angle)) / tan(angle)``; the larger of the two (the lowest point of the
    tilted part drops as far as the TCP does)."""
    d, c, tan = diameter, clearance, math.tan(angle)
    on_top = min(d * math.sin(angle), (d + c) / tan)
    inside = (d + c - d * math.cos(angle)) / tan
    return max(on_top, inside)


def wedge_lag(angle: float, friction: float, load: float, stiffness: float) -> float:
    """Twice the set-point lead (m) that slides a part tilted by ``angle`` (rad) across a
    hole edge under its tip face: the edge pushes back along the face's normal, so moving on
    takes ``load (tan(angle) + friction) / (1 - friction tan(angle))`` (N) at ``stiffness``
    (N/m); twice that, and the part is blocked (the far wall), not sliding."""
    tan = math.tan(angle)
    denom = max(1e-3, 1.0 - friction * tan)
    return 2.0 * load * (tan + friction) / denom / stiffness


class TiltState:
    """One tilted search's phase and the set-points it overrides (see the module docstring);
    ``path`` (N, 3; m): the followed trajectory's positions, for the default direction."""

    def __init__(self, cfg: TiltConfig, path: np.ndarray) -> None:
        self.cfg, self.d = cfg, cfg.unit(path)
        self.reset(0.0)

    def _tilt_to(self, angle: float) -> None:
        """Search at ``angle`` (rad) from now on."""
        self.full = angle
        self.q_tilt = self._about_axis(angle)

    def _about_axis(self, angle: float) -> np.ndarray:
        """The rotation by ``angle`` (rad) about z x d = (-d_y, d_x, 0): lowers the +d rim."""
        s = math.sin(0.5 * angle)
        return np.array([math.cos(0.5 * angle), -self.d[1] * s, self.d[0] * s, 0.0])

    def reset(self, z: float) -> None:
        self.phase, self.z_top, self.t0, self.z_aligned = SEARCH, z, 0.0, z
        self.origin = np.zeros(2)
        self.lifted = self.arrived = False  # lifting: up high enough; set-point back over
        self.z_fall, self.z_lift, self.t_lifted = z, z, 0.0  # m, m, s: the lift's course
        self.xy_fall, self.xy_lifted, self.back = np.zeros(2), np.zeros(2), np.zeros(2)
        self.edge: np.ndarray | None = None  # m, x-y of a drop that was the top's edge
        self.z_floor = -math.inf  # m, where a missed align stood upright (on the edge)
        self._tilt_to(self.cfg.angle)

    def angle(self, t: float) -> float:
        """The tilt (rad) at node time ``t``: full until aligning, then down to 0."""
        if self.phase == SEARCH and self.edge is not None:
            return 0.0
        if self.phase != ALIGN:
            return self.full
        return self.full * max(0.0, 1.0 - (t - self.t0) / self.cfg.align_time)

    def orient(self, out: np.ndarray, quat: np.ndarray, t: float) -> None:
        """``out`` = ``quat`` tilted by the phase's angle about z x d (world-side product)."""
        a = self.angle(t)
        if a >= self.full:
            quat_mul_into(out, self.q_tilt, quat)
        elif a > 0.0:
            quat_mul_into(out, self._about_axis(a), quat)
        else:
            out[:] = quat

    def step(self, pc: Percept) -> bool:
        """Advance the phase from the measured TCP; True when it should hold x-y (align)."""
        z, t = float(pc.p[2]), pc.t_node
        if self.phase == SEARCH and self.edge is not None:  # upright beside the edge
            self.z_top = z
            if float(np.hypot(*(pc.p[:2] - self.edge))) > self.cfg.lateral_reach:
                self.edge, self.t0 = None, t  # away from it: tilt again
        elif self.phase == SEARCH:
            if t - self.t0 < TILT_SETTLE:  # still tilting: no resting height yet, but
                self.z_top = max(z, self.z_floor)  # below the edge it stood on: a drop
            self.z_top = max(self.z_top, z)
            if self.z_top - z >= self.cfg.drop_depth:
                self.phase, self.t0 = LATERAL, t
                lead = float(np.dot(pc.p_d[:2] - pc.p[:2], self.d))  # the spring's pull on
                self.origin[:] = pc.p[:2] + max(0.0, lead) * self.d  # the part, kept
        if self.phase == LATERAL:
            travel = float(np.dot(pc.p[:2] - self.origin, self.d))
            lead = self.cfg.lateral_speed * (t - self.t0) - travel
            stalled = lead > self.cfg.stall_lag
            spent = travel >= self.cfg.lateral_reach or t - self.t0 > self.cfg.lateral_time
            off = self.cfg.off_depth
            if off is not None and self.z_top - z > off:  # deeper than any hole: off the top
                self.phase, self.t0, self.lifted, self.arrived = LIFT, t, False, False
                self.z_fall, self.xy_fall[:] = z, pc.p[:2]
            elif self.z_top - z < 0.5 * self.cfg.drop_depth:  # back up: the rim rode out over
                self.phase, self.t0 = SEARCH, t  # the edge (a shallow drop), search on
            elif stalled or spent:
                self.phase, self.t0 = ALIGN, t
        elif self.phase == ALIGN:
            since = t - self.t0 - self.cfg.align_time
            if since <= 0.0:
                self.z_aligned = z
            elif since > RETRY and self.z_aligned - z < RETRY_SINK:
                self.phase, self.t0 = SEARCH, t  # upright and not sinking: search on,
                self.z_floor = z
                other = self.cfg.retry_angle  # the other tilt next time
                if other is not None:
                    self._tilt_to(other if self.full == self.cfg.angle else self.cfg.angle)
        elif self.phase == LIFT:
            if not self.lifted and z >= self.z_top + 0.5 * LIFT_CLEAR:  # high enough:
                self.lifted, self.t_lifted = True, t  # over the top from here
                self.xy_lifted[:] = pc.p[:2]
            near = float(np.hypot(*(pc.p[:2] - self.back))) < LIFT_CLEAR
            if self.arrived and near:
                self.phase, self.t0 = SEARCH, t  # back over the top: search on from here,
                self.edge = self.origin.copy()  # upright until away from the edge
        return self.phase == ALIGN

    def lift(self, pc: Percept, twist: np.ndarray, target: np.ndarray) -> None:
        """In the lift phase: the set-point rises from the TCP at ``LIFT_SPEED`` until the TCP
        is ``LIFT_CLEAR`` / 2 above the top's height (the part's unsupported weight pulls it
        below the set-point, by an amount that depends on the part and the stiffness, so the
        set-point goes up until the TCP is there, and stays); then x-y moves at
        ``LIFT_SPEED`` to ``target`` (2,; m: the trajectory's x-y where it was left).
        ``twist`` (3,): the set-point's velocity."""
        self.back[:] = target
        twist[:] = 0.0
        if not self.lifted:
            self.z_lift = self.z_fall + LIFT_SPEED * (pc.t_node - self.t0)
            pc.p_d[:2], pc.p_d[2], twist[2] = self.xy_fall, self.z_lift, LIFT_SPEED
            return
        pc.p_d[2] = self.z_lift
        gap = target - self.xy_lifted
        dist = float(np.hypot(gap[0], gap[1]))
        s = LIFT_SPEED * (pc.t_node - self.t_lifted)
        self.arrived = s >= dist
        if self.arrived:
            pc.p_d[:2] = target
        else:
            pc.p_d[:2] = self.xy_lifted + gap * (s / dist)
            twist[:2] = LIFT_SPEED * gap / dist

    def lateral(self, pc: Percept, twist: np.ndarray) -> None:
        """In the lateral phase: the x-y set-point and velocity along ``d`` from the drop;
        across ``d`` the set-point is where the TCP is (no spring across: see *Free across*)."""
        pc.p_d[:2] = self.origin + self.cfg.lateral_speed * (pc.t_node - self.t0) * self.d
        n0, n1 = -self.d[1], self.d[0]
        across = (pc.p[0] - pc.p_d[0]) * n0 + (pc.p[1] - pc.p_d[1]) * n1
        pc.p_d[0] += across * n0
        pc.p_d[1] += across * n1
        twist[:2] = self.cfg.lateral_speed * self.d
