"""How the simulated blind teacher searches: its style, and the hints of a task and a robot.

:class:`TeacherStyle` holds every setting of the teacher's hand (pattern, speed, belief,
wander, press, arm stiffness, durations, tilt); a task's and a robot's
:class:`~teachfit.core.teaching.TeacherHints` adapt it to a cell and an arm
(:func:`style_for`); :func:`follow_config` says how the hand drives the compliant robot.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from teachfit.core.errors import TeachfitError
from teachfit.core.teaching import NO_TEACHER_HINTS, TeacherHints
from teachfit.robot.interface import Robot
from teachfit.skills.follow import FollowConfig
from teachfit.skills.tilt import TiltConfig
from teachfit.tasks.base import Task

PATTERNS = ("sweep", "spiral", "zigzag")


@dataclass(frozen=True)
class TeacherStyle:
    """How the simulated teacher searches (m, m/s, s, rad, N, N/m, Hz)."""

    pattern: str = "sweep"
    speed: float = 0.012
    belief_sigma: float = 0.005
    spiral_pitch: float = 0.0025
    sweep_halfwidth: float = 0.015
    wander_amplitude: float = 0.0005
    wander_timescale: float = 0.5
    #: time constant (s) of a first-order low-pass on the hand's wander and tremor, 0: none
    #: (the wander is then an Ornstein-Uhlenbeck path whose velocity is white at 100 Hz)
    hand_smoothing: float = 0.0
    tremor_amplitude: float = 0.00005
    tremor_frequency: float = 9.0
    rz_belief_sigma: float = 0.1
    rz_wiggle: float = 0.2
    rz_wiggle_frequency: float = 0.4
    push_force: float = 6.0
    press_wander: float = 0.3
    press_timescale: float = 1.0
    press_feel: float = 0.0
    arm_stiffness: float = 600.0
    max_duration: float = 60.0
    min_duration: float = 0.5
    record_rate: float = 100.0
    #: sinking (m) after which the hand stops moving the part sideways (None: never)
    hold_depth: float | None = None
    #: tilt of the held part (rad, 0: upright): leaning toward where it searches, the hand
    #: slides it to the hole's wall and turns it upright once it drops in (skills/tilt.py)
    tilt: float = 0.0
    #: how far (m) the tilted hand slides a dropped part at most (0: ``sweep_halfwidth``)
    tilt_reach: float = 0.0

    def __post_init__(self) -> None:
        if self.pattern not in PATTERNS:
            raise TeachfitError(f"teacher pattern must be one of {PATTERNS}, got {self.pattern!r}")
        positive = ("speed", "spiral_pitch", "sweep_halfwidth", "max_duration", "record_rate")
        for name in (*positive, "wander_timescale", "press_timescale"):
            if not getattr(self, name) > 0:
                raise TeachfitError(f"teacher {name} must be > 0")
        if not self.hand_smoothing >= 0:
            raise TeachfitError("teacher hand_smoothing must be >= 0")
        if not 0 <= self.press_wander < self.push_force:
            raise TeachfitError("teacher press_wander must be within [0, push_force)")
        if self.min_duration >= self.max_duration:
            raise TeachfitError("teacher min_duration must be below max_duration")


def with_hints(style: TeacherStyle, hints: TeacherHints) -> TeacherStyle:
    """``style`` with ``hints`` on the fields left at their defaults (``pattern`` only over
    the default sweep)."""
    default = TeacherStyle(pattern=style.pattern)
    given = hints.overrides()
    keep = {k: v for k, v in given.items() if getattr(style, k) == getattr(default, k)}
    if style.pattern != TeacherStyle.pattern:
        keep.pop("pattern", None)
    return dataclasses.replace(style, **keep) if keep else style


def style_for(
    task: Task, style: TeacherStyle | None = None, robot: Robot | None = None
) -> TeacherStyle:
    """``style`` (default :class:`TeacherStyle`) with the task's ``teacher_hints()``
    (:class:`~teachfit.core.teaching.TeacherHints` scaled to its cell, e.g. a mesh task's, or
    ``peg2d``'s sweep scaled to its
    clearance, chamfers and friction) -- or, for a built-in task without them,
    :func:`unchamfered_hints` -- then the ``robot``'s ``teacher_hints(task)`` (the one
    per-robot table, e.g. the FR3's press by feel and its slower hand on tasks searching in
    rz), on the fields left at their defaults (:func:`with_hints`)."""
    of_task = getattr(task, "teacher_hints", None)
    hints = of_task() if of_task is not None else unchamfered_hints(task)
    if robot is not None:
        hints = hints.then(robot.teacher_hints(task))
    return with_hints(style or TeacherStyle(), hints)


#: N/m, the lateral stiffness of a hand guiding a chamfer-free part (:func:`unchamfered_hints`):
#: the pressed part trails ~0.8 mm (floating tool) and ~2 mm (FR3) behind it; on the arm
#: 3 of 4 attempts inserted (seeds 0 and 1), 1 of 3 at the default 600 N/m
FIRM_HAND = 2000.0


def unchamfered_hints(task: Task) -> TeacherHints:
    """Hints for a task searching yaw whose entry has no chamfer at all (``puzzle``: 0.4 mm
    of play, 0.037 rad of yaw tolerance); no hints for every other task.

    With no chamfer nothing guides the part: it drops only where x, y *and* yaw fit at once.
    The default sweep (rows 2.5 mm apart, a 0.2 rad yaw wiggle) crosses that set about once
    in 200 demonstrations (0/10 recorded). A blind human aligns the part's edges with the
    block's by touch, so the yaw belief and wiggle stay inside the tolerance (as a mesh
    task's hints), and spirals around the believed hole with turns one clearance apart and a
    wander below that: a sub-millimetre sweep over the worst-case region would last minutes.
    The hand holds the part firmly (:data:`FIRM_HAND`): at the default 600 N/m the friction
    lag of the pressed part (3 mm on the floating tool, 4-7 mm on the FR3 arm) bends the
    sub-millimetre spiral, and on the arm 1 of 10 attempts crossed the hole's 0.2 mm.
    """
    p = task.params
    chamfers = [float(getattr(p, f.name)) for f in dataclasses.fields(p) if "chamfer" in f.name]
    clearance = getattr(p, "clearance", None)
    tol = getattr(task, "rz_tolerance", None)
    if "rz" not in task.search_dims or not chamfers or any(chamfers) or not clearance or not tol:
        return NO_TEACHER_HINTS
    return TeacherHints(
        pattern="spiral",
        spiral_pitch=float(clearance),
        wander_amplitude=float(clearance) / 4,
        rz_belief_sigma=float(tol) / 4,
        rz_wiggle=float(tol) / 3,
        arm_stiffness=FIRM_HAND,
    )


def follow_config(style: TeacherStyle) -> FollowConfig:
    """How the teacher's hand drives the compliant robot: its arm's stiffness in x-y, the
    follow skill's default z stiffness, its press (and ``press_feel`` loop), no settling, and
    the sideways hold once the part has dropped ``hold_depth``."""
    return FollowConfig(
        stiffness_along=style.arm_stiffness,
        stiffness_across=style.arm_stiffness,
        aligned=False,
        push_force=style.push_force,
        settle_time=0.0,
        press_feel=style.press_feel,
        hold_depth=style.hold_depth,
        tilt=_tilt(style),
    )


def _tilt(style: TeacherStyle) -> TiltConfig | None:
    """The hand's tilted search (``style.tilt`` > 0): it feels the drop at ``hold_depth``
    (0.5 mm without one), slides the part on by up to ``sweep_halfwidth`` or ``tilt_reach``
    (its soft arm pressing the low rim on the hole's far wall as it goes) and turns it
    upright."""
    if style.tilt <= 0.0:
        return None
    drop, reach = style.hold_depth or 5e-4, max(style.sweep_halfwidth, style.tilt_reach)
    return TiltConfig(angle=style.tilt, drop_depth=drop, lateral_reach=reach, stall_lag=reach)
