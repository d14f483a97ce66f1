"""Conditions over the percept: when transitions fire, when a skill succeeds or fails.

Johannsmeier et al. 2019 (Def. 1) defines a condition as ``c(x) in C`` for a closed set ``C`` of
some function of the percept ``x``. Here a condition is a frozen spec (TOML-able, validated) that
:meth:`Condition.compile` turns, once per execution and with the parameter values resolved,
into a plain ``percept -> bool`` function (stateful ones, like a sustained low speed, carry
their state in the closure and restart with :meth:`Check.restart` when their node is entered).

TOML form: ``{ kind = "force_above", axis = "+z", value = "f_contact" }``; composites
``{ all = [...] }``, ``{ any = [...] }``, ``{ not = {...} }``. A value is a number or a
parameter name (see :mod:`teachfit.skills.params`).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from teachfit.core.errors import SkillError
from teachfit.skills.params import Value, ref_name, resolve
from teachfit.skills.percept import Percept

Check = Callable[[Percept], bool]

_AXES = {
    "+x": (0, 1.0),
    "-x": (0, -1.0),
    "+y": (1, 1.0),
    "-y": (1, -1.0),
    "+z": (2, 1.0),
    "-z": (2, -1.0),
}


def _fmt(value: Value, unit: str) -> str:
    return f"{value:g} {unit}".strip() if isinstance(value, int | float) else str(value)


class Condition(ABC):
    """A condition spec; see the module docstring."""

    kind: ClassVar[str]

    @abstractmethod
    def compile(self, values: Mapping[str, float]) -> Check:
        """A ``percept -> bool`` function with parameters resolved from ``values``."""

    @abstractmethod
    def describe(self) -> str:
        """Short human-readable form, for figures and listings."""

    @abstractmethod
    def to_toml(self) -> dict[str, Any]:
        """The TOML inline-table form."""

    def refs(self) -> set[str]:
        """Names of the parameters this condition uses."""
        return {n for v in self._values() if (n := ref_name(v)) is not None}

    def _values(self) -> tuple[Value, ...]:
        return ()

    def __and__(self, other: Condition) -> Condition:
        return All((self, other))

    def __or__(self, other: Condition) -> Condition:
        return Any_((self, other))

    def __invert__(self) -> Condition:
        return Not(self)


@dataclass(frozen=True)
class _Threshold(Condition):
    value: Value

    unit: ClassVar[str] = ""

    def __post_init__(self) -> None:
        ref_name(self.value)  # type check

    def _values(self) -> tuple[Value, ...]:
        return (self.value,)

    def to_toml(self) -> dict[str, Any]:
        return {"kind": self.kind, "value": self.value}


@dataclass(frozen=True)
class ForceAbove(_Threshold):
    """Environment force along a task axis (``"+z"``: pushing the tool up) or its lateral
    (``"xy"``) or total (``"norm"``) magnitude is at least ``value`` (N)."""

    axis: str = "norm"
    kind: ClassVar[str] = "force_above"
    unit: ClassVar[str] = "N"

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.axis not in (*_AXES, "xy", "norm"):
            raise SkillError(f"force_above: axis must be one of {[*_AXES, 'xy', 'norm']}")

    def compile(self, values: Mapping[str, float]) -> Check:
        thr = resolve(self.value, values)
        if self.axis == "xy":
            return lambda pc: math.hypot(pc.f[0], pc.f[1]) >= thr
        if self.axis == "norm":
            return lambda pc: math.hypot(pc.f[0], pc.f[1], pc.f[2]) >= thr
        i, sign = _AXES[self.axis]
        return lambda pc: sign * pc.f[i] >= thr

    def describe(self) -> str:
        return f"F[{self.axis}] ≥ {_fmt(self.value, 'N')}"

    def to_toml(self) -> dict[str, Any]:
        return {"kind": self.kind, "axis": self.axis, "value": self.value}


@dataclass(frozen=True)
class TimeAbove(_Threshold):
    """Time since the node (``scope="node"``) or the skill (``"skill"``) started >= value (s)."""

    scope: str = "node"
    kind: ClassVar[str] = "time_above"

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.scope not in ("node", "skill"):
            raise SkillError(f"time_above: scope must be 'node' or 'skill', got {self.scope!r}")

    def compile(self, values: Mapping[str, float]) -> Check:
        thr = resolve(self.value, values)
        if self.scope == "node":
            return lambda pc: pc.t_node >= thr
        return lambda pc: pc.t >= thr

    def describe(self) -> str:
        return f"t_{self.scope} ≥ {_fmt(self.value, 's')}"

    def to_toml(self) -> dict[str, Any]:
        return {"kind": self.kind, "scope": self.scope, "value": self.value}


@dataclass(frozen=True)
class DepthAbove(_Threshold):
    """The TCP is at least ``value`` (m) below the task frame's x-y plane (depth reached)."""

    kind: ClassVar[str] = "depth_above"

    def compile(self, values: Mapping[str, float]) -> Check:
        thr = resolve(self.value, values)
        return lambda pc: -pc.p[2] >= thr

    def describe(self) -> str:
        return f"depth ≥ {_fmt(self.value, 'm')}"


@dataclass(frozen=True)
class LateralAbove(_Threshold):
    """The TCP is at least ``value`` (m) from the task z-axis (e.g. it left the ROI)."""

    kind: ClassVar[str] = "lateral_above"

    def compile(self, values: Mapping[str, float]) -> Check:
        thr = resolve(self.value, values)
        return lambda pc: math.hypot(pc.p[0], pc.p[1]) >= thr

    def describe(self) -> str:
        return f"|p_xy| ≥ {_fmt(self.value, 'm')}"


@dataclass(frozen=True)
class XBelow(_Threshold):
    """The TCP's task-frame x is at most ``value`` (m) (e.g. a move along -x went past the
    hole)."""

    kind: ClassVar[str] = "x_below"

    def compile(self, values: Mapping[str, float]) -> Check:
        thr = resolve(self.value, values)
        return lambda pc: pc.p[0] <= thr

    def describe(self) -> str:
        return f"p_x ≤ {_fmt(self.value, 'm')}"


@dataclass(frozen=True)
class RemainingBelow(_Threshold):
    """The TCP is within ``value`` (m) of the active primitive's goal."""

    kind: ClassVar[str] = "remaining_below"

    def compile(self, values: Mapping[str, float]) -> Check:
        thr = resolve(self.value, values)
        return lambda pc: pc.remaining <= thr  # NaN (no goal) compares False

    def describe(self) -> str:
        return f"|p - goal| ≤ {_fmt(self.value, 'm')}"


@dataclass(frozen=True)
class TiltBelow(_Threshold):
    """The tool axis is within ``value`` (rad) of the task z-axis."""

    kind: ClassVar[str] = "tilt_below"

    def compile(self, values: Mapping[str, float]) -> Check:
        thr = resolve(self.value, values)
        return lambda pc: pc.tilt <= thr

    def describe(self) -> str:
        return f"tilt ≤ {_fmt(self.value, 'rad')}"


@dataclass(frozen=True)
class SpeedBelow(_Threshold):
    """The TCP's lateral (``axes="xy"``) or total (``"xyz"``) speed has stayed below
    ``value`` (m/s) for ``duration`` (s) within the current node: it is constrained."""

    duration: Value = 0.05
    axes: str = "xy"
    kind: ClassVar[str] = "speed_below"

    def __post_init__(self) -> None:
        super().__post_init__()
        ref_name(self.duration)
        if self.axes not in ("xy", "xyz"):
            raise SkillError(f"speed_below: axes must be 'xy' or 'xyz', got {self.axes!r}")

    def _values(self) -> tuple[Value, ...]:
        return (self.value, self.duration)

    def compile(self, values: Mapping[str, float]) -> Check:
        thr, hold = resolve(self.value, values), resolve(self.duration, values)
        state = {"since": math.inf, "last": -math.inf}
        n = 2 if self.axes == "xy" else 3

        def check(pc: Percept) -> bool:
            if pc.t_node < state["last"]:  # node re-entered: forget
                state["since"] = math.inf
            state["last"] = pc.t_node
            slow = math.sqrt(sum(pc.v[i] * pc.v[i] for i in range(n))) < thr
            if not slow:
                state["since"] = math.inf
                return False
            state["since"] = min(state["since"], pc.t_node)
            return pc.t_node - state["since"] >= hold

        return check

    def describe(self) -> str:
        return f"|v_{self.axes}| < {_fmt(self.value, 'm/s')} for {_fmt(self.duration, 's')}"

    def to_toml(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "axes": self.axes,
            "value": self.value,
            "duration": self.duration,
        }


@dataclass(frozen=True)
class DepthStalled(_Threshold):
    """For ``duration`` (s) within the current node the TCP has not got ``value`` (m) deeper
    than where it last did: pushing on makes no progress (a jammed or missed part)."""

    duration: Value = 1.0
    kind: ClassVar[str] = "depth_stalled"

    def __post_init__(self) -> None:
        super().__post_init__()
        ref_name(self.duration)

    def _values(self) -> tuple[Value, ...]:
        return (self.value, self.duration)

    def compile(self, values: Mapping[str, float]) -> Check:
        gain, hold = resolve(self.value, values), resolve(self.duration, values)
        state = {"ref": -math.inf, "since": 0.0, "last": -math.inf}

        def check(pc: Percept) -> bool:
            depth = -float(pc.p[2])
            if pc.t_node < state["last"] or depth >= state["ref"] + gain:  # (re-)entered, deeper
                state["ref"], state["since"] = depth, pc.t_node
            state["last"] = pc.t_node
            return pc.t_node - state["since"] >= hold

        return check

    def describe(self) -> str:
        return f"depth gains < {_fmt(self.value, 'm')} in {_fmt(self.duration, 's')}"

    def to_toml(self) -> dict[str, Any]:
        return {"kind": self.kind, "value": self.value, "duration": self.duration}


@dataclass(frozen=True)
class Done(Condition):
    """The active primitive finished its own motion (e.g. its velocity profile)."""

    kind: ClassVar[str] = "done"

    def compile(self, values: Mapping[str, float]) -> Check:
        return lambda pc: pc.done

    def describe(self) -> str:
        return "done"

    def to_toml(self) -> dict[str, Any]:
        return {"kind": self.kind}


@dataclass(frozen=True)
class Detected(Condition):
    """The task's success detector holds: from what the robot measures (its TCP pose) the
    part is in the hole (see ``Task.detect_success``)."""

    kind: ClassVar[str] = "detected"

    def compile(self, values: Mapping[str, float]) -> Check:
        return lambda pc: pc.detected

    def describe(self) -> str:
        return "task detects success"

    def to_toml(self) -> dict[str, Any]:
        return {"kind": self.kind}


@dataclass(frozen=True)
class All(Condition):
    """All of ``parts`` hold."""

    parts: tuple[Condition, ...]
    kind: ClassVar[str] = "all"

    def __post_init__(self) -> None:
        if not self.parts or not all(isinstance(c, Condition) for c in self.parts):
            raise SkillError(f"{self.kind}: needs one or more conditions")
        object.__setattr__(self, "parts", tuple(self.parts))

    def refs(self) -> set[str]:
        return set().union(*(c.refs() for c in self.parts))

    def compile(self, values: Mapping[str, float]) -> Check:
        checks = [c.compile(values) for c in self.parts]
        return lambda pc: all([chk(pc) for chk in checks])  # evaluate all: stateful parts

    def describe(self) -> str:
        return " ∧ ".join(_paren(c) for c in self.parts)

    def to_toml(self) -> dict[str, Any]:
        return {self.kind: [c.to_toml() for c in self.parts]}


@dataclass(frozen=True)
class Any_(All):
    """At least one of ``parts`` holds."""

    kind: ClassVar[str] = "any"

    def compile(self, values: Mapping[str, float]) -> Check:
        checks = [c.compile(values) for c in self.parts]
        return lambda pc: any([chk(pc) for chk in checks])

    def describe(self) -> str:
        return " ∨ ".join(_paren(c) for c in self.parts)


@dataclass(frozen=True)
class Not(Condition):
    """``part`` does not hold."""

    part: Condition
    kind: ClassVar[str] = "not"

    def refs(self) -> set[str]:
        return self.part.refs()

    def compile(self, values: Mapping[str, float]) -> Check:
        chk = self.part.compile(values)
        return lambda pc: not chk(pc)

    def describe(self) -> str:
        return f"¬{_paren(self.part)}"

    def to_toml(self) -> dict[str, Any]:
        return {"not": self.part.to_toml()}


def _paren(c: Condition) -> str:
    return f"({c.describe()})" if isinstance(c, All) else c.describe()


_LEAVES: dict[str, type[Condition]] = {
    c.kind: c
    for c in (
        ForceAbove,
        TimeAbove,
        DepthAbove,
        LateralAbove,
        XBelow,
        RemainingBelow,
        TiltBelow,
        SpeedBelow,
        DepthStalled,
        Done,
        Detected,
    )
}


def condition_from_toml(data: Mapping[str, Any]) -> Condition:
    """A condition from its TOML inline-table form (see the module docstring)."""
    if not isinstance(data, Mapping):
        raise SkillError(f"a condition must be a table, got {data!r}")
    for key, cls in (("all", All), ("any", Any_)):
        if key in data:
            if set(data) != {key} or not isinstance(data[key], list):
                raise SkillError(f"'{key}' must be the only key and hold a list: {dict(data)}")
            return cls(tuple(condition_from_toml(d) for d in data[key]))
    if "not" in data:
        if set(data) != {"not"}:
            raise SkillError(f"'not' must be the only key: {dict(data)}")
        return Not(condition_from_toml(data["not"]))
    kind = data.get("kind")
    if kind not in _LEAVES:
        raise SkillError(
            f"unknown condition kind {kind!r}; known: {sorted(_LEAVES)} (or all/any/not)"
        )
    kwargs = {k: v for k, v in data.items() if k != "kind"}
    try:
        return _LEAVES[kind](**kwargs)
    except TypeError as exc:
        raise SkillError(f"condition {kind!r}: {exc}") from exc
