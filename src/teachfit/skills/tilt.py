"""Searching with a tilted part: tilt, feel the drop, slide to the wall, align (Johannsmeier et
al.'s ``tilt``, ``lateral`` and ``align`` primitives as the nodes of a search graph).

An upright sharp-edged peg drops into its hole only when its axis passes within the radial
clearance of the hole's (0.1-0.25 mm in the peg2d variants). Tilted by ``angle`` about the
horizontal axis z x d, its lowest point is one rim point, ``d`` (a fixed task-frame direction:
by default from the trajectory's start toward its centroid, the part leaning toward where it
searches) from the axis; that point drops as soon as it is over the hole, deep enough to
feel near the hole's line along ``d`` (millimetres, not tenths; see *Lead* below).
The search then runs these phases, each a node of a skill graph
(:mod:`teachfit.skills.tilt_graph`: the primitives in :mod:`teachfit.skills.tilt_phases`, the
conditions that move it on in :mod:`teachfit.skills.tilt_conditions`, what the phases share in
:class:`~teachfit.skills.tilt_context.TiltContext`):

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
   from where the trajectory was left (the trajectory's clock stands still outside the
   search nodes, and the set-point blends back to it);
4. *lift*: a drop in the lateral phase deeper than ``off_depth`` (a tilted part enters a
   hole far less deep than the hole is) was the part leaving the top over its outer edge,
   the low rim first (Ø 30 mm, 0.5 mm, μ 0.5: a 58 mm "drop" 46 mm from the hole on a Ø 120
   mm top: the low rim went over the edge, the part pivoted on it and slid down the block's
   side for the whole reach, and then stood on the floor beside the block, pushed there,
   until the time ran out). Without the push, the set-point rises until the TCP is
   ``LIFT_CLEAR`` / 2 above the top's height, then moves at ``LIFT_SPEED`` back over the top
   to where the trajectory was left (``lift``, then ``back``), and the search goes on from
   there upright (``upright``; upright,
   a part whose axis is over the top stays on it) until the TCP is ``lateral_reach`` from
   where the drop was felt; then tilted again (tilted there again, the low rim went over the
   same edge again: the same fall, lift and return, over and over).

Lead. The point that feels the hole is the low rim, ``r cos(angle)`` ahead of the axis along
``d``; a trajectory planned for where the hole may be is planned for that point, so the
follower moves its set-points back by ``lead`` along ``d`` (:func:`rim_lead`; ramped in over
``LEAD_TIME`` at the start). The tilt itself turns in from upright over ``ramp_time`` (s,
0: at once) where a config asks: the parts suite's sharp round parts, searched alone on the
floating tool (10 starts), found their holes 8/10 and 7/10 (round8, round16) with the tilt at
once and 9/10 and 10/10 with it turned in over 0.5 s. Without the lead the rim swept the
planned region shifted a radius ahead, and a wide part's tour passed with the rim 10-14 mm
from the hole's centre (Ø 30 mm,
0.5 mm, μ 0.5, 5 of 20 starts): the part sinks deep enough to feel only where the rim is
near the hole's line along ``d`` (offset across it, its neighbours on the rim rest on the top
beside the hole and it sinks a fraction of a millimetre).

Corners. A non-round part (``corner``: the angle of its corner from the task x, rad) leans
toward its corner nearest ``d``: a flat side dips only where it lies within the clearance
of the hole's line, a corner wherever it is over the hole (rect12x8-sharp-through searched
alone on the FR3, 10 starts: 1-2/10 leaning along the path, 10/10 toward the corner; two
rectangles nobody tuned for, 10x10 and 20x8 mm: 2/10 each before, 10/10 and 9/10 after).

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


#: the drops that may turn out missed within a tilted search's time budget (:attr:`extra_time`)
MISSES = 3


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
    ramp_time: float = 0.0
    corner: float | None = None

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
        if not (math.isfinite(self.ramp_time) and self.ramp_time >= 0.0):
            raise SkillError(f"tilt: ramp_time must be >= 0 s, got {self.ramp_time}")
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
        """The time (s) the budget adds for :data:`MISSES` drops, each the longest lateral and
        align phases: the tour's clock stands still in them, so a search whose first drops
        turn out missed still follows its whole tour (on the FR3, round16-sharp-blind at a
        fresh seed: 3 of 12 starts ran out of time after 1-3 missed drops), and a drop at the
        trajectory's end still gets them."""
        return MISSES * (self.lateral_time + self.align_time)

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
        d = v / n if n > 1e-9 else np.array([1.0, 0.0])
        if self.corner is None:
            return d
        # a non-round part leans toward its corner nearest d: a corner dips from anywhere over
        # the hole, a flat side only within the clearance of the hole's line
        ends = [(sx * math.cos(self.corner), sy * math.sin(self.corner)) for sx in (1, -1)
                for sy in (1, -1)]  # fmt: skip
        return np.array(max(ends, key=lambda e: e[0] * d[0] + e[1] * d[1]))


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
