"""The joined skill's learned search, tilted for a sharp-edged part: nodes of its graph.

Upright, a sharp-edged part drops into its hole only when its axis passes within the
clearance of the hole's (0.1 mm per side on the parts suite), which the learned tours rarely
pass (:mod:`teachfit.skills.tilt`). Tilted by ``search_tilt`` (rad, 0: upright, the default),
its low rim dips over the hole from millimetres. :class:`LearnedTiltSearch` is the joined
skill's ``search`` node (:mod:`teachfit.skills.peg_in_hole_search`): upright it is
:class:`~teachfit.skills.search.LearnedSearch` unchanged; tilted it plans the same TSHIX tour
from where the skill is and follows it as the first phase of a tilted search
(:class:`~teachfit.skills.tilt_phases.TiltedSearch`). The tilted search's next phases are
nodes of the joined graph too (:func:`tilt_nodes`)::

    search --drop felt--> search_slide --at the wall--> search_align --missed--> search
       ^                       |
       +------rode out---------+

and the search and the tilted align end in the skill's ``align`` once the part is
``drop_depth`` in. The slide does not: a tilted part's low corner dips that deep while it
slides (rect12x8-sharp-through), and turned upright there, short of the far wall, it stood
on the edge, was pushed, searched again and slid in again, 17 times until ``t_max`` (2 of
10 trials).
A tour that ends without a catch is followed by a fresh one from where it ended
(``search_repeat``), with a fresh tilted search. While the part tilts at the start of a tour,
its height where the tour started counts as the reference height a drop is felt below (as
after a missed align): a part that stopped at the hole's edge (the far wall, where the skill's
lateral move gave up) drops in while it tilts, before a resting height could be measured
(round16-sharp-blind: 0.9 mm in, tilted, and the tour dragged it to the force limit). The
orientation set-point turns to the tilt over :data:`TILT_BLEND` from the measured
orientation where the tour starts, and where the search goes on after a missed align (the
skill's own lateral tilt leans another way; the missed align stands upright): on
the FR3 the step to the tilt at once threw the part 5-10 mm sideways and 5 mm up, off the
top and into the force limit (rect12x8-sharp-through, 6 of 10 trials).

The part leans toward the taught hole, or, tilted already (the skill's lateral move), 45
degrees from the way it leans, toward the taught hole's side (:func:`lean_of`); the tour
starts at its low rim, which the tilted search makes follow the tour (its ``lead``). On
the FR3 (rect12x8-sharp-through, where the skill's last pass ended 6 mm beyond the taught
hole) a tour started at the part's axis first pulled the part back by the lead, 6 mm, and a
lean toward the taught hole rolled the part from the lateral move's low rim over its tip
onto the other; either threw it 5-10 mm sideways and up to 10 mm up, off the top, into the
force limit; tilted again at once after a missed align, the part jumped 5-7 mm and felt
false drops (round16-sharp-blind on the FR3: slides of 16 mm, and off the top). Leaning the
lateral move's way (along x) kept a rectangular part's whole short
side lowest, which drops only where it fits the hole within the clearance (a tour without
a drop); turned 45 degrees, a corner leads and the tilt turns in without a roll.

The part is pressed by the push alone along z in every phase (the set-point's height follows
the TCP, as the upright search does: the adaptive controller's learned feed-forward would
otherwise cancel the push). The tilt's settings are the skill's context, which a task that
knows its fit sets (:mod:`teachfit.skills.fit_context`): ``search_retry_tilt`` (rad, 0: none)
after each missed align, alternating; ``search_drop`` (m) the sink below the tilted resting
height that is felt as a drop; ``search_reach`` (m) the slide's reach (a hole's width);
``search_lead`` (m) how far the low rim leads the axis (the tour is planned for the rim);
``search_friction``: the stall lag at the far wall is :func:`~teachfit.skills.tilt.wedge_lag`
of the tilt, this friction, the push and the follower's stiffness along the motion.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.core.errors import SkillError
from teachfit.core.geometry import rotation_to_wxyz, wxyz_to_rotation
from teachfit.models.search_model import SearchModel
from teachfit.skills.conditions import Check, Condition
from teachfit.skills.graph import Node, Transition
from teachfit.skills.params import Value, resolve
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.primitive import Primitive, PrimitiveRun
from teachfit.skills.search import LearnedSearch, Tour, plan_tour
from teachfit.skills.tilt import TiltConfig, wedge_lag
from teachfit.skills.tilt_conditions import AtWall, DropFelt, Missed, RodeOut
from teachfit.skills.tilt_context import KEY, TiltContext
from teachfit.skills.tilt_phases import TiltedSearch, TiltPhase

#: time (s) over which a tour's orientation set-point turns from the measured orientation
#: where it started to its tilt (see the module docstring)
TILT_BLEND = 0.5
#: tilt (rad) above which a tour's part leans near the way it leans (:func:`lean_of`), and
#: how far (rad) the lean turns from it
LEAN_MIN, LEAN_TURN = 0.05, np.pi / 4
#: the tilted search's phases after the search node: node name -> phase
PHASE_NODES = {"search_slide": "slide_to_wall", "search_align": "align_upright"}


def _pressed(pc: Percept, out: MPCommand) -> None:
    """Along z only the push presses: the set-point's height follows the TCP."""
    pc.p_d[2] = pc.p[2]
    out.twist[2] = 0.0


@dataclass(frozen=True)
class LearnedTiltSearch(LearnedSearch):
    """The learned search, tilted by ``tilt`` (rad; 0: upright, :class:`LearnedSearch`);
    see the module docstring for the other settings."""

    tilt: Value = "search_tilt"
    retry_tilt: Value = "search_retry_tilt"
    drop: Value = "search_drop"
    reach: Value = "search_reach"
    lead: Value = "search_lead"
    friction: Value = "search_friction"
    kind: ClassVar[str] = "learned_tilt_search"

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        angle = resolve(self.tilt, values)
        if angle <= 0.0:
            return super().compile(values)
        tour = self.tour(values)
        retry = resolve(self.retry_tilt, values)
        cfg = tour.cfg
        friction = resolve(self.friction, values)
        stall = wedge_lag(angle, friction, cfg.push_force, cfg.stiffness_along)
        tilt = TiltConfig(
            angle=angle,
            retry_angle=retry if 0.0 < retry < angle else None,
            drop_depth=resolve(self.drop, values),
            lateral_reach=resolve(self.reach, values),
            stall_lag=stall,
            lead=resolve(self.lead, values),
        )
        return _TiltedTourRun(self.model, replace(tour, cfg=replace(cfg, tilt=tilt)))

    def describe(self) -> str:
        return f"{super().describe()}, tilted {self.tilt} rad"


def lean_of(pc: Percept) -> np.ndarray:
    """The side (2,), task frame, a tour's tilted part leans to (its low rim): toward the
    taught hole (the task frame's origin; +x right over it); where the part is tilted by more
    than :data:`LEAN_MIN` already (the skill's lateral move), the side it leans to turned by
    :data:`LEAN_TURN` toward the taught hole's side of it."""
    toward = -pc.p[:2]
    n = float(np.hypot(toward[0], toward[1]))
    toward = toward / n if n > 1e-6 else np.array([1.0, 0.0])
    axis = wxyz_to_rotation(pc.q).as_matrix()[:2, 2]  # the tilt about z x d moves it along d
    n = float(np.hypot(axis[0], axis[1]))
    if n <= np.sin(LEAN_MIN):
        return toward
    lean = axis / n
    turn = LEAN_TURN if lean[0] * toward[1] - lean[1] * toward[0] >= 0.0 else -LEAN_TURN
    c, s = np.cos(turn), np.sin(turn)
    return np.array([c * lean[0] - s * lean[1], s * lean[0] + c * lean[1]])


class _TiltedTourRun(PrimitiveRun):
    """The search node's run, tilted: a tour planned from here followed as a tilted
    search's first phase; re-entered after a missed align it goes on with the same tour."""

    def __init__(self, model: SearchModel, tour: Tour) -> None:
        self.model, self.tour = model, tour
        self.inner: PrimitiveRun | None = None
        self.q_entry, self.t_entry = np.array([1.0, 0.0, 0.0, 0.0]), 0.0

    def _plan(self, pc: Percept) -> None:
        t, tilt = self.tour, self.tour.cfg.tilt
        assert tilt is not None
        d = lean_of(pc)
        shift = (tilt.lead * float(d[0]), tilt.lead * float(d[1]))  # the low rim: the start
        traj = plan_tour(self.model, t.planner, t.n, t.rng, pc, blend=False, shift=shift)
        pc.shared.pop(KEY, None)  # a fresh tilted search: its context is made on entry
        cfg = replace(t.cfg, tilt=replace(tilt, direction=float(np.arctan2(d[1], d[0]))))
        self.inner = TiltedSearch(traj, cfg).compile({})
        self.inner.enter(pc)
        ctx = pc.shared[KEY]
        assert isinstance(ctx, TiltContext)
        ctx.z_floor = float(pc.p[2])  # a part that drops in as it tilts has dropped
        ctx.blend_time = 0.0  # the tour starts at the rim: the axis stays where it is
        self.q_entry, self.t_entry = pc.q.copy(), pc.t

    def enter(self, pc: Percept) -> None:
        if self.inner is None or not isinstance(pc.shared.get(KEY), TiltContext):
            self._plan(pc)
        else:  # after a missed align (upright on the edge): tilted again, blended too
            self.inner.enter(pc)
            self.q_entry, self.t_entry = pc.q.copy(), pc.t

    def command(self, pc: Percept, out: MPCommand) -> None:
        assert self.inner is not None, "enter() first"
        self.inner.command(pc, out)
        _pressed(pc, out)
        share = (pc.t - self.t_entry) / TILT_BLEND
        if share < 1.0:  # from the orientation the tour started in
            r0 = wxyz_to_rotation(self.q_entry)
            turn = (r0.inv() * wxyz_to_rotation(pc.q_d)).as_rotvec()
            pc.q_d[:] = rotation_to_wxyz(r0 * Rotation.from_rotvec(max(0.0, share) * turn))
        if pc.done and self.tour.repeat:  # a tour without a catch: another one from here
            self._plan(pc)

    def leave(self, pc: Percept) -> None:
        assert self.inner is not None, "enter() first"
        self.inner.leave(pc)


@dataclass(frozen=True)
class PressedPhase(Primitive):
    """A tilted search's ``phase`` (:class:`~teachfit.skills.tilt_phases.TiltPhase`) with
    the part pressed by the push alone along z (see the module docstring)."""

    phase: str
    kind: ClassVar[str] = "pressed_tilt_phase"

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        return _PressedRun(TiltPhase(self.phase).compile(values))

    def describe(self) -> str:
        return f"{TiltPhase(self.phase).describe()}, pressed along z"

    def refs(self) -> set[str]:
        return set()

    def to_toml(self) -> dict[str, Any]:
        raise SkillError("a tilted search's phase runs inside its graph only: no TOML form")


class _PressedRun(PrimitiveRun):
    def __init__(self, inner: PrimitiveRun) -> None:
        self.inner = inner

    def enter(self, pc: Percept) -> None:
        self.inner.enter(pc)

    def command(self, pc: Percept, out: MPCommand) -> None:
        self.inner.command(pc, out)
        _pressed(pc, out)

    def leave(self, pc: Percept) -> None:
        self.inner.leave(pc)


@dataclass(frozen=True)
class Tilted(Condition):
    """A tilted search runs (its context is published) and ``part`` holds; never upright
    (where a tilted search's own conditions have no context to read)."""

    part: Condition
    kind: ClassVar[str] = "tilted"

    def compile(self, values: Mapping[str, float]) -> Check:
        inner = self.part.compile(values)
        return lambda pc: isinstance(pc.shared.get(KEY), TiltContext) and inner(pc)

    def describe(self) -> str:
        return f"tilted: {self.part.describe()}"

    def to_toml(self) -> dict[str, Any]:
        raise SkillError("a tilted search's condition runs inside its graph only: no TOML form")


def tilt_nodes(
    error: Condition, dropped: Condition, caught: str
) -> tuple[tuple[Node, ...], tuple[Transition, ...]]:
    """The nodes after the joined skill's ``search`` (:data:`PHASE_NODES`, ``error`` their
    error exit) and the transitions among them and from ``search``; ``dropped``: the part is
    in, on to the skill's node ``caught``."""
    nodes = tuple(
        Node(
            name,
            PressedPhase(phase),
            error=error,
            doc=phase,
            reset_setpoint=False,
            chain=name == "search_slide",
        )  # fmt: skip
        for name, phase in PHASE_NODES.items()
    )
    transitions = (
        Transition("search", "search_slide", Tilted(DropFelt())),
        Transition("search_align", caught, dropped),
        Transition("search_slide", "search", RodeOut()),
        Transition("search_slide", "search_align", AtWall()),
        Transition("search_align", "search", Missed()),
    )
    return nodes, transitions
