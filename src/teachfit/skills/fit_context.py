"""The peg-in-hole skill's context for a part whose fit the task knows: low rim first.

Johannsmeier et al.'s lateral move (:mod:`teachfit.skills.peg_in_hole`) leans the part so that
its *trailing* rim is lowest and slides it along +x from ``lateral_offset`` before the taught
hole. Into a chamfered entry that works; into a sharp-edged hole with a tight fit it does not.
Measured on the ``round-peg`` example (Ø 8 mm, 0.1 mm per side, taught hole off by 0.5 mm per
axis; 5 held-out set-ups, 0/10): the tilted bottom face fits the hole only when the axis is
within about the clearance of the hole's across the move, so where the taught hole was 0.30-0.49
mm off across it the part slid over the hole with the TCP never below the entry (the 1 mm that
marks a catch needs more than the ``D sin(tilt)`` = 0.8 mm the low rim can drop) until it left
the region of interest (6/10); where it was 0.03-0.21 mm off, the high leading rim caught on
the far edge at the entry (0.1-0.2 mm below it) and ``align``, turning upright about the TCP,
lifted the part out onto the top 0.3-1.1 mm past the axis, where ``insert`` pressed 31.7 N
without sinking until it stalled (4/10).

A task that knows its fit (``part_half_width`` ``r``, ``clearance`` ``c`` per side,
``tip_chamfer`` ``e`` of the part, ``params.hole_pos_sigma`` ``sigma``; m) gets the tilted
search's way instead (:mod:`teachfit.skills.tilt`): the part slides along -x
(``lateral_dir = -1``) with its *leading* rim lowest, which dips over the hole and slides to
the far wall, free across the move (``k_across = 0``: the round wall centres it), and turns
upright about that rim into the hole. With ``R = r + c`` the hole's half width:

* start the rim beyond the hole's near edge when the taught hole is ``3 sigma`` off toward it:
  ``lateral_offset = -(r + R + 3 sigma)`` (the approach pose on the +x side), at most the
  task's ``detection_radius`` (beyond it the part would land off the top or in another hole);
* passes: a part as wide as its hole rests on the top beside it unless it is within a few
  tenths of a millimetre of the hole's line (round-peg: caught 0.5 mm across, missed 0.7-1.5
  mm), so a move that went ``pass_end = R`` past the taught axis (x <= -R) missed and the
  next pass starts ``pass_y = 2 sigma`` to one side, then to the other: three lines cover
  ``3 sigma`` across when a pass catches within ``sigma`` of its line (round-peg, taught hole
  0.5-1.5 mm off across: 1/6 inserted with one pass, 6/6 with three, both robots);
* ``roi = hypot(|lateral_offset|, pass_y) + 1 mm``: beyond every start;
* the far wall: a resistance along +x of ``f_lateral_rev = 2 f_lateral`` (``f_lateral``,
  along -x, never fires), or the part stopped, counts only with the TCP below the entry
  (``wall_depth = 0``) or within ``wall_x = c + 3 sigma`` of the taught axis along x (where
  the far wall is): on the FR3 (which presses 4-10 N as it lands) the near edge under the
  tilted face resisted the slide with 4.1 N and the seam between the plate's convex pieces
  5.1 mm from the axis stopped the part at 5-8 N, both with the TCP 0.2-0.3 mm above the
  entry, and the part turned upright there stood on the top; a part centred on the hole's
  line may stop at the far edge without dipping (TCP 0.4 mm above the entry, 0.1 mm past
  the axis);
* the tilt domain ``(0, min(0.3, acos((r - e) / R), align_tilt))``: turning upright about
  the far wall, the high rim clears the near edge for any depth (*Jams* in
  :mod:`teachfit.skills.tilt`);
* ``t_lateral = (|lateral_offset| + R) / (v_lateral s_low)`` with ``s_low`` the lowest learned
  ``speed_factor``: the slowest move still reaches the far wall; ``t_max`` grows by as much as
  ``t_lateral`` does over its default, plus two passes of ``t_lateral + 1 s``; a skill that
  gives the lateral move up early (the joined skill's switch to a search,
  :mod:`teachfit.skills.peg_in_hole_search`) waits ``t_reach = |lateral_offset| / (v_lateral
  s_low)``, the slowest move's time to the taught axis;
* the tilt at most :attr:`FitGeometry.align_tilt`, ``r sin(tilt) <= 0.45 mm``: ``align``
  turns the part upright about the TCP, which lifts the low rim, caught at the far wall, by
  ``r sin(tilt)`` and lowers the high one as much onto the near edge. With the skill's 0.1
  rad a part 16 mm wide (``r`` 8 mm, 0.8 mm) stood on the top after the turn, 1.1 mm off the
  axis (round16-sharp-blind and rect16x10-chamfer-blind on the floating tool, 10 held-out
  set-ups: 0/10 each); at 0.075 rad (0.6 mm) 11/20 and 4/20, at 0.06 and 0.05 rad 20/20
  each on both robots; a part 8 mm wide keeps 0.1 rad (0.4 mm; the round-peg example 20/20);
* a sharp non-round part (``corner`` ``w``: its half width across the move) goes corner
  first (:func:`corner_context`): its leading rim is flat, and dips only where it lies within
  the clearance of the hole's width across the move (rect12x8-sharp-through, 20 held-out
  set-ups: 0/20 on the floating tool, 11/20 on the FR3). Rolled so that the rim's -y corner is
  lowest, it dips wherever that corner is over the hole and, moved along ``(-1, -1)`` and stiff
  both ways, slides along the first wall it meets into the hole's corner, where the part lies
  within the clearance of the hole: 20/20 on both robots, and on three rectangles nobody
  tuned for (10x10, 20x8, 14x9 mm, seed 3: 8, 0, 0/20 floating and 15, 12, 12/20 on the FR3
  before, 20/20 each after). Along ``(-1, -0.5)`` the friction of the corner on the far wall
  held it 0.4 mm short of the side wall on the FR3 (16/20). The roll lifts the low corner
  too when the part turns upright: ``align_tilt`` leaves it ``w sin(roll)`` less;
* a sharp leading rim (``e < c``) is pressed with half the default ``f_push``: pressed with
  4 N it caught on the seam between the plate's convex pieces (a resistance of 4.2 N along
  +x with the TCP still on the top, 4 of 10 executions); with 2 N it slid over it (10/10);
* a sharp leading rim is learned at a tilt of at least half the domain's largest
  (:data:`SHARP_TILT_SHARE`): the less it leans, the less its rim dips where it crosses the
  hole off the pass's line, and the narrower the band a pass catches across. Learned down to
  0.024 rad (round8-sharp-through, CMA-ES over 130 trials of 8 set-ups, each 100 % on them),
  the part passed over the hole on 6 of 20 held-out set-ups whose taught hole was 0.4-0.6
  mm across the line (66/80 executions); the same parameters at 0.06 rad (half of 0.116)
  80/80, at 0.1 rad 78/80.

Tasks without the three attributes (the built-in ones) keep Johannsmeier et al.'s context.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from teachfit.core.errors import SkillError
from teachfit.core.params import ParamDomain
from teachfit.skills.tilt import rim_lead

#: the roi beyond the start of the lateral move (m)
ROI_MARGIN = 0.001
#: a force threshold that never fires (N): above any force limit
NEVER = 1000.0
#: the far wall's resistance, times the default f_lateral
WALL_SHARE = 2.0
#: time (s) the approach and contact of an extra pass take at most
PASS_TIME = 1.0
#: share of the default press a sharp leading rim gets (see the module docstring)
SHARP_PUSH = 0.5
#: the least learned tilt of a sharp leading rim, as a share of its largest (see the module
#: docstring)
SHARP_TILT_SHARE = 0.5
#: the most the low rim may rise (m) when ``align`` turns the part upright about the TCP
#: (see the module docstring)
ALIGN_RISE = 4.5e-4
#: a sharp non-round part's corner-first lateral move (:func:`corner_context`): the move's
#: slope across, the roll (rad) and the stiffness across (N/m)
CORNER_SLOPE, CORNER_ROLL, CORNER_K = 1.0, 0.04, 1500.0
#: the joined skill's search tilt for a sharp-edged part (rad) and the sink felt as a drop
#: (m): those of the tilted search on the sharp-edged task variants (``peg2d``)
SEARCH_TILT, SEARCH_DROP = 0.25, 2.5e-4


@dataclass(frozen=True)
class FitGeometry:
    """A part's fit in its hole (m): ``half_width`` ``r`` of the part along the lateral move,
    ``clearance`` ``c`` per side, the part's ``tip_chamfer`` ``e`` (0: a sharp edge) and the
    taught hole's position error ``sigma`` per axis; ``reach``: how far from the hole the
    part stays over the top surface (inf: unknown); ``corner``: a non-round part's half width
    across the move (m; 0: round)."""

    half_width: float
    clearance: float
    tip_chamfer: float
    sigma: float
    reach: float = math.inf
    friction: float = 0.3
    corner: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.half_width) and self.half_width > 0):
            raise SkillError(f"fit: half_width must be > 0 m, got {self.half_width}")
        for name in ("clearance", "tip_chamfer", "sigma"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise SkillError(f"fit: {name} must be >= 0 m, got {value}")
        if self.tip_chamfer >= self.half_width:
            raise SkillError(
                f"fit: tip_chamfer ({self.tip_chamfer}) must be below half_width "
                f"({self.half_width})"
            )

    @property
    def hole_half_width(self) -> float:
        """``R = r + c`` (m)."""
        return self.half_width + self.clearance

    @property
    def align_tilt(self) -> float:
        """``asin(ALIGN_RISE / r)`` (rad): the largest tilt whose turn upright about the TCP
        lifts the low rim by at most :data:`ALIGN_RISE` (``r sin(tilt)``); a part moved corner
        first (:func:`corner_context`) less the roll's share, ``w sin(CORNER_ROLL)``."""
        rise = ALIGN_RISE
        if self.corner > 0.0 and self.tip_chamfer < self.clearance:
            rise -= self.corner * math.sin(CORNER_ROLL)
        return math.asin(min(1.0, max(0.25 * ALIGN_RISE, rise) / self.half_width))

    @property
    def max_tilt(self) -> float:
        """``acos((r - e) / R)`` (rad): the largest tilt that turns upright without a jam."""
        return math.acos((self.half_width - self.tip_chamfer) / self.hole_half_width)


def fit_of(task: object) -> FitGeometry | None:
    """The task's fit, or None when it lacks ``part_half_width``, ``clearance`` or
    ``tip_chamfer`` (the built-in tasks)."""
    vals = [getattr(task, n, None) for n in ("part_half_width", "clearance", "tip_chamfer")]
    if not all(isinstance(v, int | float) for v in vals):
        return None
    params = getattr(task, "params", None)
    sigma = float(getattr(params, "hole_pos_sigma", 0.0) or 0.0)
    friction = getattr(params, "friction", None)
    reach = getattr(task, "detection_radius", None)
    r, c, e = (float(v) for v in vals if isinstance(v, int | float))
    across = getattr(task, "part_half_depth", None)
    round_ = not float(getattr(task, "rz_period", 0.0) or 0.0) > 0.0
    return FitGeometry(
        r,
        c,
        e,
        sigma,
        float(reach) if isinstance(reach, int | float) else math.inf,
        float(friction) if isinstance(friction, int | float) else FitGeometry.friction,
        0.0 if round_ or not isinstance(across, int | float) else float(across),
    )


def fit_context(
    fit: FitGeometry, defaults: dict[str, float], speed_low: float, tilt: ParamDomain
) -> tuple[dict[str, float], dict[str, ParamDomain]]:
    """The context values and learned domains of a low-rim-first lateral move for ``fit``
    (see the module docstring); ``defaults``: the skill's context defaults (``v_lateral``,
    ``t_lateral``, ``t_max``, ``f_lateral``, ``f_push``), ``speed_low`` the lowest
    ``speed_factor``, ``tilt`` the skill's own tilt domain (the fit only narrows it)."""
    big_r = fit.hole_half_width
    start = min(fit.half_width + big_r + 3.0 * fit.sigma, fit.reach)
    t_lateral = max(defaults["t_lateral"], (start + big_r) / (defaults["v_lateral"] * speed_low))
    sharp = fit.tip_chamfer < fit.clearance
    press = SHARP_PUSH if sharp else 1.0
    pass_y = 2.0 * fit.sigma
    values = {
        "f_push": press * defaults["f_push"],
        "lateral_dir": -1.0,
        "lateral_offset": -start,
        "roi": math.hypot(start, pass_y) + ROI_MARGIN,
        "k_across": 0.0,
        "f_lateral": NEVER,
        "f_lateral_rev": WALL_SHARE * defaults["f_lateral"],
        "wall_depth": 0.0,
        "wall_x": fit.clearance + 3.0 * fit.sigma,
        "pass_end": big_r,
        "pass_y": pass_y,
        "t_lateral": t_lateral,
        "t_reach": start / (defaults["v_lateral"] * speed_low),
        "t_max": defaults["t_max"]
        + t_lateral
        - defaults["t_lateral"]
        + 2.0 * (t_lateral + PASS_TIME),
    }
    if sharp:
        values |= search_tilt_context(fit)
        if fit.corner > 0.0:
            values |= corner_context(fit, values, start)
    high = min(tilt.high, fit.max_tilt, fit.align_tilt)
    low = min(high, max(tilt.low, SHARP_TILT_SHARE * high)) if sharp else tilt.low
    return values, {"tilt": ParamDomain(low, high)}


def corner_context(fit: FitGeometry, values: dict[str, float], start: float) -> dict[str, float]:
    """A sharp non-round part's lateral move, corner first: rolled by :data:`CORNER_ROLL` so
    that the leading rim's -y corner is lowest, moved along ``(-1, -a)`` with ``a`` =
    :data:`CORNER_SLOPE` from ``(start, a start)`` through the taught axis, stiff across
    (:data:`CORNER_K`) so that the corner, once in the hole, slides along one wall into the
    hole's corner; the times grow with the longer path."""
    a = CORNER_SLOPE
    stretch = math.hypot(1.0, a)
    t_lateral = values["t_lateral"] * stretch
    return {
        "lateral_dir_y": -a,
        "start_y": a * start,
        "roll": CORNER_ROLL,
        "k_across": CORNER_K,
        "roi": math.hypot(start, a * start + values["pass_y"]) + ROI_MARGIN,
        "t_lateral": t_lateral,
        "t_reach": values["t_reach"] * stretch,
        "t_max": values["t_max"] + 3.0 * (t_lateral - values["t_lateral"]),
    }


def search_tilt_context(fit: FitGeometry) -> dict[str, float]:
    """The joined skill's tilted search for a sharp-edged part
    (:mod:`teachfit.skills.search_tilted`): tilted :data:`SEARCH_TILT`, after a missed
    align alternately at the jam-free :attr:`FitGeometry.max_tilt` where that is smaller; a
    drop felt at :data:`SEARCH_DROP`; the slide reaching the hole's width; the rim's lead for
    a part ``2 r`` wide; the fit's friction."""
    retry = fit.max_tilt if fit.max_tilt < SEARCH_TILT else 0.0
    return {
        "search_tilt": SEARCH_TILT,
        "search_retry_tilt": retry,
        "search_drop": SEARCH_DROP,
        "search_reach": 2.0 * fit.hole_half_width,
        "search_lead": rim_lead(SEARCH_TILT, 2.0 * fit.half_width),
        "search_friction": fit.friction,
    }
