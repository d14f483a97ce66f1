"""Johannsmeier et al.'s peg-in-hole skill whose recovery is Ehlers et al.'s learned search (the
methods joined).

The graph is :func:`teachfit.skills.peg_in_hole.build`'s with one more node, ``search``
(:class:`~teachfit.skills.search.LearnedSearch`), and more transitions::

    approach -> contact -> lateral --constrained--> align -> insert  (success: depth)
                              |                       ^        |
                    gave up: t_switch or roi          |   stuck: t_stuck without dropping
                              v                       |        v
                              +-----------------> search <-----+
                                      dropped in: drop_depth -> align

    insert --stalled after dropping in--> realign -> reinsert  (a stall there: error)

``lateral`` gives up after the learned ``t_switch`` (or on leaving the region of interest)
instead of failing, but not before ``t_reach``, the time the move needs to reach the taught
hole (0 for Johannsmeier et al.'s short move; a task that knows its fit starts the move a part's
width and more before the hole, :mod:`teachfit.skills.fit_context`: switching after 0.8 s
there searched before the part had reached the hole). Such a task's extra passes
(``lateral_2``, ``lateral_3``) give up alike, and the last one's miss (``-pass_end``) searches
too. ``insert`` gives up after pushing ``t_stuck`` without the part dropping
below the surface (the lateral move stopped on a false constraint). Both enter the search,
which ends with the part caught in the hole (``drop_depth`` below the entry) -> ``align`` ->
``insert``, or with ``t_search`` over -> error -> ``retract`` (a tour that ends without a catch
is followed by a fresh one from where it ended, ``search_repeat``: a tight sharp-edged fit is
caught only within about its clearance of the hole's axis, and one tour of the default points
took 7-8 s of the 15 s on the parts suite's 8 mm round part; 0: the tour done ends it). An
``insert`` that stalls with the part already dropped in is aligned and pushed once more from
where the part stands (``realign``, ``reinsert``; :func:`_insert_once_more` says why).

With ``search_tilt`` > 0 (a sharp-edged part whose fit the task knows,
:mod:`teachfit.skills.fit_context`) the search follows its tours tilted, with two more
nodes, ``search_slide`` and ``search_align`` (:mod:`teachfit.skills.search_tilted`); 0 (the
default): upright, as above.

Learned, besides Johannsmeier et al.'s: ``t_switch``, ``t_stuck`` (when to switch to search) and the
search's ``search_points``, ``search_scale``, ``search_speed``, ``search_push``; the meta
learners tune them with the rest. Context adds ``t_search``, ``search_seed``,
``search_radius`` (how far off the taught hole may be: the search's spread in the surface plane
is scaled up to at least this RMS radius, as a human who searched a narrower region than the
error needs; :func:`~teachfit.skills.search.recentred`) and raises the skill's ``t_max`` to
leave time for a search.
"""

from __future__ import annotations

from dataclasses import replace

from teachfit.core.params import ParamDomain
from teachfit.models.search_model import SearchModel
from teachfit.skills import peg_in_hole
from teachfit.skills.conditions import (
    Condition,
    DepthAbove,
    DepthStalled,
    Done,
    ForceAbove,
    LateralAbove,
    TimeAbove,
    XBelow,
)
from teachfit.skills.graph import Node, Skill, Transition
from teachfit.skills.params import ContextParam, LearnedParam, SkillParams
from teachfit.skills.search_tilted import LearnedTiltSearch, tilt_nodes

NAME = "peg-in-hole+search"

CONTEXT: dict[str, ContextParam] = {
    "t_max": ContextParam(25.0, "s", "time limit of the skill, search included"),
    "t_lateral": ContextParam(3.0, "s", "hard time limit of the lateral move"),
    "t_search": ContextParam(15.0, "s", "time limit of the search"),
    "search_seed": ContextParam(0.0, "", "seed of the search's samples"),
    "search_repeat": ContextParam(
        1.0, "", "1: a tour without a catch is followed by another until t_search (0: one)"
    ),
    "t_reach": ContextParam(0.0, "s", "lateral time before t_switch counts: to the hole"),
    "search_radius": ContextParam(
        0.0, "m", "least RMS radius of the search's spread: the taught hole's error (0: none)"
    ),
    "search_tilt": ContextParam(0.0, "rad", "tilt of the searching part (0: upright)"),
    "search_retry_tilt": ContextParam(0.0, "rad", "tilt after a missed tilted align (0: none)"),
    "search_drop": ContextParam(2.5e-4, "m", "tilted: sink below its resting height = a drop"),
    "search_reach": ContextParam(0.01, "m", "tilted: reach of the slide after a drop"),
    "search_lead": ContextParam(0.0, "m", "tilted: how far the low rim leads the axis"),
    "search_friction": ContextParam(0.3, "", "tilted: friction of the rim on the far wall"),
}

LEARNED: dict[str, LearnedParam] = {
    "t_switch": LearnedParam(0.8, ParamDomain(0.2, 2.0), "s", "lateral time before searching"),
    "t_stuck": LearnedParam(0.6, ParamDomain(0.2, 2.0), "s", "insert time without drop, search"),
    "search_points": LearnedParam(60.0, ParamDomain(10.0, 200.0), "", "TSHIX samples"),
    "search_scale": LearnedParam(0.5, ParamDomain(0.1, 1.5), "", "scales the human's spread"),
    "search_speed": LearnedParam(1.0, ParamDomain(0.5, 2.0), "", "scales the teacher's speed"),
    "search_push": LearnedParam(6.0, ParamDomain(2.0, 12.0), "N", "push onto the surface"),
}


#: the lateral moves of the base skill's passes (the extra two only for a task that knows its fit)
LATERALS = ("lateral", "lateral_2", "lateral_3")
#: the base skill's nodes run once more, from where the part stalled in the hole
SEAT = ("align", "insert")


def _insert_once_more(node: Node, stalled_in: Condition) -> Node:
    """``insert`` whose stall in the hole (``stalled_in``) is no error but the way to
    ``realign`` -> ``reinsert``: the part fell in during the push, away from the set-point the
    push started from (its oscillation centred there, the adaptive law's stiffness growing on
    the offset the walls hold: the part jams short of the success depth); from where it stands
    now it is pushed in once more. Other nodes unchanged."""
    if node.name != "insert" or node.error is None:
        return node
    return replace(node, error=node.error & ~stalled_in)


def build(model: SearchModel, controller: str = "adaptive") -> Skill:
    """The joined skill with search ``model`` (learned on the same kind of task)."""
    base = peg_in_hole.build(controller)
    params = SkillParams(
        dict(base.params.context) | CONTEXT, dict(base.params.learned) | dict(LEARNED)
    )
    dropped = DepthAbove("drop_depth")
    stalled = DepthStalled("stall_depth", "stall_time")
    nodes = tuple(
        replace(n, error=TimeAbove("t_lateral")) if n.name in LATERALS else n for n in base.nodes
    )
    nodes = tuple(_insert_once_more(n, stalled & dropped) for n in nodes)
    # a resistance away from where the far wall is expected: the hole is off by more than
    # the fit's sigma (pushing on reaches f_max), so search from here
    stopped = TimeAbove("t_settle") & ForceAbove("f_lateral_rev", axis="+x")
    gave_up = (TimeAbove("t_switch") & TimeAbove("t_reach")) | LateralAbove("roi") | stopped
    search = Node(
        "search",
        LearnedTiltSearch(model),
        TimeAbove("t_search") | Done(),
        "learned search (TSHIX + GMR feed-forward) from where the skill is, tilted or not",
    )
    phases, tilted = tilt_nodes(TimeAbove("t_search"), dropped, "align")
    transitions = base.transitions + (
        *(Transition(lateral, "search", gave_up) for lateral in LATERALS),
        Transition(LATERALS[-1], "search", XBelow("-pass_end")),
        Transition("insert", "search", TimeAbove("t_stuck") & ~dropped),
        Transition("search", "align", dropped),
        *tilted,
        Transition("insert", "realign", stalled & dropped),
        Transition("realign", "reinsert", Done()),
    )
    again = tuple(replace(n, name="re" + n.name) for n in base.nodes if n.name in SEAT)
    return Skill(
        name=NAME,
        nodes=nodes + (search, *phases, *again),
        transitions=transitions,
        start=base.start,
        params=params,
        success=base.success,
        error=base.error,
        pre=base.pre,
        recovery=base.recovery,
        doc="Johannsmeier et al.'s peg-in-hole whose recovery is Ehlers et al.'s learned search",
    )
