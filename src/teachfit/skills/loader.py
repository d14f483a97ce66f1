"""Skills from and to TOML.

Layout (see ``examples/skills/peg_in_hole.toml``)::

    [skill]
    name = "peg-in-hole"
    start = "approach"
    recovery = "retract"                              # optional: one of [nodes.*]
    success = { kind = "depth_above", value = "depth" }
    error = { any = [ { kind = "time_above", scope = "skill", value = "t_max" }, ... ] }
    pre = { not = { kind = "force_above", axis = "norm", value = "f_contact" } }   # optional

    [context]
    depth = { value = 0.0105, unit = "m", doc = "..." }

    [learned]
    force = { default = 8.0, low = 2.0, high = 20.0, log = false, unit = "N", doc = "..." }

    [nodes.approach]                                  # in graph order
    primitive = "move_to"
    goal = ["-lateral_offset", 0.0, "approach_height"]
    error = { kind = "time_above", scope = "node", value = "t_approach" }

    [[transitions]]
    from = "approach"
    to = "contact"
    when = { all = [ { kind = "done" }, { kind = "remaining_below", value = 0.001 } ] }

Values are numbers or (optionally negated) parameter names. The skill is validated as it is
built, so a bad file fails with a :class:`~teachfit.core.errors.SkillError` naming the node.
Python's standard library reads TOML but does not write it; :func:`skill_to_toml` writes this
one layout (tables of scalars, arrays and inline tables) itself.
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from teachfit.core.errors import SkillError
from teachfit.core.params import LearningError, ParamDomain
from teachfit.skills.conditions import condition_from_toml
from teachfit.skills.graph import Node, Skill, Transition
from teachfit.skills.params import ContextParam, LearnedParam, SkillParams
from teachfit.skills.primitive import primitive_from_toml

_NODE_KEYS = {"error", "doc", "reset_setpoint", "keep_orientation"}


def _table(data: Mapping[str, Any], key: str, where: str) -> dict[str, Any]:
    val = data.get(key, {})
    if not isinstance(val, Mapping):
        raise SkillError(f"{where}: [{key}] must be a table")
    return dict(val)


def _node(name: str, data: Mapping[str, Any]) -> Node:
    try:
        prim = primitive_from_toml({k: v for k, v in data.items() if k not in _NODE_KEYS})
        err = condition_from_toml(data["error"]) if "error" in data else None
    except SkillError as exc:
        raise SkillError(str(exc), node=name) from exc
    reset, keep = bool(data.get("reset_setpoint", True)), bool(data.get("keep_orientation", False))
    return Node(name, prim, err, str(data.get("doc", "")), reset, keep_orientation=keep)


def skill_from_dict(data: Mapping[str, Any], where: str = "skill") -> Skill:
    """A skill from the parsed TOML layout in the module docstring."""
    head = _table(data, "skill", where)
    for key in ("name", "start", "success", "error"):
        if key not in head:
            raise SkillError(f"{where}: [skill] needs {key!r}")
    try:
        context = {n: ContextParam(**v) for n, v in _table(data, "context", where).items()}
        learned = {}
        for n, v in _table(data, "learned", where).items():
            v = dict(v)
            dom = ParamDomain(v.pop("low"), v.pop("high"), bool(v.pop("log", False)))
            learned[n] = LearnedParam(domain=dom, **v)
    except (TypeError, KeyError, LearningError) as exc:
        raise SkillError(f"{where}: invalid parameter table: {exc}") from exc
    nodes_data = _table(data, "nodes", where)
    rec_name = head.get("recovery")
    if rec_name is not None and rec_name not in nodes_data:
        raise SkillError(f"{where}: recovery node {rec_name!r} has no [nodes.{rec_name}] table")
    nodes = [_node(n, v) for n, v in nodes_data.items() if n != rec_name]
    recovery = _node(rec_name, nodes_data[rec_name]) if rec_name is not None else None
    transitions = []
    for tr in data.get("transitions", []):
        if set(tr) != {"from", "to", "when"}:
            raise SkillError(
                f"{where}: a transition needs exactly from, to, when; got {sorted(tr)}"
            )
        try:
            transitions.append(Transition(tr["from"], tr["to"], condition_from_toml(tr["when"])))
        except SkillError as exc:
            raise SkillError(f"transition to {tr['to']!r}: {exc}", node=tr["from"]) from exc
    return Skill(
        name=str(head["name"]),
        nodes=tuple(nodes),
        transitions=tuple(transitions),
        start=str(head["start"]),
        params=SkillParams(context, learned),
        success=condition_from_toml(head["success"]),
        error=condition_from_toml(head["error"]),
        pre=condition_from_toml(head["pre"]) if "pre" in head else None,
        recovery=recovery,
        doc=str(head.get("doc", "")),
        frame=str(head.get("frame", Skill.frame)),
    )


def load_skill(path: str | Path) -> Skill:
    """A skill from a TOML file; errors name the file (and the node)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise SkillError(f"cannot read skill file {path}: {exc}") from exc
    try:
        return skill_from_dict(data, str(path))
    except SkillError as exc:
        err = SkillError(f"{path}: {exc}")
        err.node = exc.node
        raise err from exc


# ---------------------------------------------------------------------------------- writing
def skill_to_dict(skill: Skill) -> dict[str, Any]:
    """The TOML layout of ``skill`` as nested dicts (``None`` fields left out)."""
    head: dict[str, Any] = {
        "name": skill.name,
        "doc": skill.doc,
        "frame": skill.frame,
        "start": skill.start,
    }
    if skill.recovery is not None:
        head["recovery"] = skill.recovery.name
    head["success"] = skill.success.to_toml()
    head["error"] = skill.error.to_toml()
    if skill.pre is not None:
        head["pre"] = skill.pre.to_toml()
    context = {
        n: {"value": p.value, "unit": p.unit, "doc": p.doc} for n, p in skill.params.context.items()
    }
    learned = {
        n: {
            "default": p.default,
            "low": p.domain.low,
            "high": p.domain.high,
            "log": p.domain.log,
            "unit": p.unit,
            "doc": p.doc,
        }
        for n, p in skill.params.learned.items()
    }
    nodes = {}
    for node in skill.nodes + ((skill.recovery,) if skill.recovery else ()):
        table = node.primitive.to_toml()
        assert node.error is not None  # a skill's nodes all have an error exit
        table["error"] = node.error.to_toml()
        table["doc"] = node.doc
        table["reset_setpoint"] = node.reset_setpoint
        if node.keep_orientation:
            table["keep_orientation"] = True
        nodes[node.name] = table
    transitions = [
        {"from": t.source, "to": t.target, "when": t.condition.to_toml()} for t in skill.transitions
    ]
    return {
        "skill": head,
        "context": context,
        "learned": learned,
        "nodes": nodes,
        "transitions": transitions,
    }


_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k: str) -> str:
    return k if _BARE.match(k) else json.dumps(k, ensure_ascii=False)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise SkillError(f"cannot write {v!r} to TOML")


def skill_to_toml(skill: Skill) -> str:
    """``skill`` as TOML text that :func:`load_skill` reads back to an equal skill."""
    d = skill_to_dict(skill)
    out = [f"# skill {skill.name!r}: written by teachfit", "", "[skill]"]
    out += [f"{_key(k)} = {_value(v)}" for k, v in d["skill"].items()]
    for section in ("context", "learned"):
        out += ["", f"[{section}]"]
        out += [f"{_key(k)} = {_value(v)}" for k, v in d[section].items()]
    for name, table in d["nodes"].items():
        out += ["", f"[nodes.{_key(name)}]"]
        out += [f"{_key(k)} = {_value(v)}" for k, v in table.items()]
    for tr in d["transitions"]:
        out += ["", "[[transitions]]"]
        out += [f"{_key(k)} = {_value(v)}" for k, v in tr.items()]
    return "\n".join(out) + "\n"
