"""A tilted search as a skill graph: one node per phase (:mod:`teachfit.skills.tilt`)::

    search --drop felt--> lateral --left the top--> lift --high enough--> back
       ^                  |  |                                              |
       +----rode out------+  +--at the wall--> align                   returned
       +---------------------------missed-------+                          v
       +------------------------away from the edge------------------- upright

``lateral`` is a ``chain`` node: a drop felt with the part already deeper than any hole or
against the wall leaves it in the same command. ``lift``, ``back`` and ``upright`` exist
only with an ``off_depth``. The phases share the execution's
:class:`~teachfit.skills.tilt_context.TiltContext`.
"""

from __future__ import annotations

from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills.conditions import Condition
from teachfit.skills.follower import FollowConfig
from teachfit.skills.graph import Node, Transition
from teachfit.skills.primitive import Primitive
from teachfit.skills.tilt_conditions import (
    AtWall,
    AwayFromEdge,
    DropFelt,
    HighEnough,
    LeftTop,
    Missed,
    Returned,
    RodeOut,
)
from teachfit.skills.tilt_phases import TiltedSearch, TiltPhase

#: the phases' node names, the search first
NODES = ("search", "lateral", "align", "lift", "back", "upright")


def tilted_search_graph(
    trajectory: SetpointTrajectory, cfg: FollowConfig, error: Condition
) -> tuple[tuple[Node, ...], tuple[Transition, ...]]:
    """The nodes (``search`` first: the start) and transitions of a tilted search of
    ``trajectory`` with ``cfg`` (its ``tilt`` set); ``error``: every phase's error exit."""
    tilt = cfg.tilt
    assert tilt is not None

    def node(name: str, primitive: Primitive, doc: str, chain: bool = False) -> Node:
        return Node(name, primitive, error=error, doc=doc, reset_setpoint=False, chain=chain)

    nodes = [
        node("search", TiltedSearch(trajectory, cfg), "tilted, the low rim feels for a drop"),
        node(
            "lateral", TiltPhase("slide_to_wall"), "the low rim slides to the far wall", chain=True
        ),
        node("align", TiltPhase("align_upright"), "turning upright about the rim on the far wall"),
    ]
    off: list[Transition] = []
    if tilt.off_depth is not None:
        nodes += [
            node("lift", TiltPhase("lift_off"), "the part went over the top's edge: up"),
            node("back", TiltPhase("back_over_top"), "back over the top"),
            node("upright", TiltPhase("upright_search"), "upright until a reach from that edge"),
        ]
        off = [Transition("lateral", "lift", LeftTop())]
    transitions = [
        Transition("search", "lateral", DropFelt()),
        *off,
        Transition("lateral", "search", RodeOut()),
        Transition("lateral", "align", AtWall()),
        Transition("align", "search", Missed()),
    ]
    if tilt.off_depth is not None:
        transitions += [
            Transition("lift", "back", HighEnough()),
            Transition("back", "upright", Returned()),
            Transition("upright", "search", AwayFromEdge()),
        ]
    return tuple(nodes), tuple(transitions)
