"""The skill graph (Johannsmeier et al. 2019, Sec. III): primitives as nodes, transitions fired by
conditions.

A :class:`Skill` is a directed graph ``G = (N, E)`` of :class:`Node` s (each one manipulation
primitive with its own error condition) and :class:`Transition` s (each fired by a condition,
checked in declaration order). Around it: a precondition (may the skill start?), a success
condition (stop, positive: the edge to the terminal node, checked in every node), a global
error condition (stop, negative, e.g. the time limit) and a recovery node run after an error.
Parameters are :class:`~teachfit.skills.params.SkillParams`.

A skill is validated when built; every problem raises :class:`~teachfit.core.errors.SkillError`
naming the node at fault: an unreachable node, a primitive without an error exit, a transition
to an unknown node, a reference to an undeclared parameter, a learned default outside its
domain, or a primitive whose resolved values are invalid (e.g. a negative speed).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property

from teachfit.core.errors import SkillError
from teachfit.core.params import ParamDomain, ParamSpace
from teachfit.skills.conditions import Check, Condition
from teachfit.skills.params import SkillParams
from teachfit.skills.primitive import Primitive, PrimitiveRun


@dataclass(frozen=True)
class Node:
    """A manipulation primitive in the graph; ``error`` is its error exit (to recovery).

    ``reset_setpoint``: the node starts from the measured pose (the set-point of the previous
    node may have run ahead of a constrained part); ``False`` continues from the commanded
    set-point. ``keep_orientation`` (with ``reset_setpoint``): the position starts from the
    measured one, the orientation from the commanded one -- a part that sags under gravity,
    friction or contact does not ratchet the commanded orientation over repeated entries.
    ``chain``: entered by a transition, its own transitions are checked at once, in the same
    command period (a phase that may end as soon as it begins).
    """

    name: str
    primitive: Primitive
    error: Condition | None = None
    doc: str = ""
    reset_setpoint: bool = True
    chain: bool = False
    keep_orientation: bool = False

    def refs(self) -> set[str]:
        return self.primitive.refs() | (self.error.refs() if self.error else set())


@dataclass(frozen=True)
class Transition:
    """``source -> target`` once ``condition`` holds (the source's success condition)."""

    source: str
    target: str
    condition: Condition


@dataclass(frozen=True)
class CompiledNode:
    """A node ready to run: its primitive, its error check and its outgoing transitions."""

    name: str
    run: PrimitiveRun
    error: Check
    reset_setpoint: bool
    transitions: tuple[tuple[Check, int, str], ...]  # (check, target index, description)
    chain: bool = False
    keep_orientation: bool = False


@dataclass(frozen=True)
class Skill:
    """A validated skill graph; see the module docstring."""

    name: str
    nodes: tuple[Node, ...]
    transitions: tuple[Transition, ...]
    start: str
    params: SkillParams
    success: Condition
    error: Condition
    pre: Condition | None = None
    recovery: Node | None = None
    doc: str = ""
    frame: str = field(default="estimated hole frame (z out of the surface)")

    def __post_init__(self) -> None:
        object.__setattr__(self, "nodes", tuple(self.nodes))
        object.__setattr__(self, "transitions", tuple(self.transitions))
        self._validate()

    # ----------------------------------------------------------------------- validation
    def _validate(self) -> None:
        if not self.nodes:
            raise SkillError(f"skill {self.name!r} has no nodes")
        names = [n.name for n in self.nodes]
        for node in self._all_nodes():
            if not node.name or not node.name.replace("-", "_").isidentifier():
                raise SkillError("node names must be identifiers", node=node.name)
            if not isinstance(node.primitive, Primitive):
                raise SkillError("a node needs a primitive", node=node.name)
            if node.error is None:
                raise SkillError(
                    "primitive has no error exit (set its error condition)", node=node.name
                )
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup or (self.recovery is not None and self.recovery.name in names):
            clash = (dup or [self.recovery.name]) if self.recovery is not None else dup
            raise SkillError(f"duplicate node name(s) {clash}")
        if self.start not in names:
            raise SkillError(f"start node {self.start!r} is not a node; nodes: {names}")
        for tr in self.transitions:
            if tr.source not in names:
                raise SkillError(f"transition from unknown node {tr.source!r}", node=tr.source)
            if tr.target not in names:
                raise SkillError(
                    f"transition to unknown node {tr.target!r}; nodes: {names}", node=tr.source
                )
            if tr.source == tr.target:
                raise SkillError("transition to itself", node=tr.source)
        reached = {self.start}
        frontier = [self.start]
        while frontier:
            here = frontier.pop()
            for tr in self.transitions:
                if tr.source == here and tr.target not in reached:
                    reached.add(tr.target)
                    frontier.append(tr.target)
        for name in names:
            if name not in reached:
                raise SkillError(f"unreachable from the start node {self.start!r}", node=name)
        known = self.params.names
        for node in self._all_nodes():
            refs = node.refs() | set().union(
                *(t.condition.refs() for t in self.transitions if t.source == node.name)
            )
            missing = sorted(refs - known)
            if missing:
                raise SkillError(f"undeclared parameter(s) {missing}", node=node.name)
        glob = set().union(*(c.refs() for c in (self.success, self.error, self.pre) if c))
        if glob - known:
            raise SkillError(f"skill conditions use undeclared parameter(s) {sorted(glob - known)}")
        # learned defaults inside their domains, and every primitive valid with them
        self.compile(self.params.defaults)

    def _all_nodes(self) -> tuple[Node, ...]:
        return self.nodes + ((self.recovery,) if self.recovery is not None else ())

    # --------------------------------------------------------------------------- queries
    @property
    def space(self) -> ParamSpace:
        """The learned parameters' :class:`ParamSpace` (what a learner searches)."""
        return self.params.space

    def node(self, name: str) -> Node:
        for n in self._all_nodes():
            if n.name == name:
                return n
        raise SkillError(f"skill {self.name!r} has no node {name!r}")

    def users(self) -> dict[str, list[str]]:
        """Parameter name -> names of the nodes using it (primitive, error, transitions)."""
        return {name: list(nodes) for name, nodes in self._users.items()}

    @cached_property
    def _users(self) -> dict[str, list[str]]:
        """:meth:`users`, worked out once per skill (frozen): every execution resolves its
        parameters against it, and walking the graph's references cost ~2.5 ms each time."""
        out: dict[str, list[str]] = {}
        for node in self._all_nodes():
            refs = node.refs() | set().union(
                *(t.condition.refs() for t in self.transitions if t.source == node.name)
            )
            for r in refs:
                out.setdefault(r, []).append(node.name)
        return out

    def with_context(self, values: Mapping[str, float]) -> Skill:
        """The same skill with context parameter values replaced (e.g. from a task)."""
        return replace(self, params=self.params.with_context(values))

    def with_fixed(self, values: Mapping[str, float]) -> Skill:
        """The same skill with some learned parameters fixed (moved to the context) at
        ``values``: a task that does not learn them (see :meth:`SkillParams.with_fixed`)."""
        return replace(self, params=self.params.with_fixed(values))

    def with_domains(self, domains: Mapping[str, ParamDomain], why: str = "") -> Skill:
        """The same skill with some learned parameters searched over other domains (see
        :meth:`SkillParams.with_domains`)."""
        return replace(self, params=self.params.with_domains(domains, why))

    # ------------------------------------------------------------------------- compiling
    def resolve(self, learned: Mapping[str, float] | None = None) -> dict[str, float]:
        """All parameter values: context + learned (validated; defaults fill gaps)."""
        checked = self.params.check_learned(learned or {}, self.users())
        return self.params.all_values(checked)

    def compile(
        self, learned: Mapping[str, float] | None = None
    ) -> tuple[list[CompiledNode], CompiledNode | None, Check, Check, Check | None]:
        """Runnable nodes (index = position in :attr:`nodes`), recovery, success, error, pre.

        Values out of their domains or invalid for a primitive raise :class:`SkillError`
        naming the node.
        """
        values = self.resolve(learned)
        index = {n.name: i for i, n in enumerate(self.nodes)}

        def build(node: Node) -> CompiledNode:
            try:
                run = node.primitive.compile(values)
                assert node.error is not None  # _validate checked every error exit
                err = node.error.compile(values)
                trs = tuple(
                    (t.condition.compile(values), index[t.target], t.condition.describe())
                    for t in self.transitions
                    if t.source == node.name
                )
            except SkillError as exc:
                if exc.node is not None:
                    raise
                raise SkillError(str(exc), node=node.name) from exc
            return CompiledNode(
                node.name, run, err, node.reset_setpoint, trs, node.chain, node.keep_orientation
            )

        nodes = [build(n) for n in self.nodes]
        rec = build(self.recovery) if self.recovery is not None else None
        pre = self.pre.compile(values) if self.pre is not None else None
        return nodes, rec, self.success.compile(values), self.error.compile(values), pre
