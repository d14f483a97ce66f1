"""Skill parameters: context parameters set by the task, learned parameters with domains.

Following Johannsmeier et al. 2019 (Sec. III), the parameter set ``P`` of a skill splits into
``P_C``, fixed by the context of the task (estimated hole pose, depth, approach height, region of
interest, system limits), and ``P_L``, the parameters to learn, each inside a domain derived from
system and safety limits. The learned domains form a :class:`~teachfit.learning.base.ParamSpace`, so
a learner consumes a skill's space directly.

Primitive and condition fields are :data:`Value` s: a number, or a reference to a parameter by
name (``"force"``), optionally negated (``"-lateral_offset"``). References are resolved once
per execution, never in the control loop.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from teachfit.core.atomic import atomic_write_text
from teachfit.core.errors import OutputError, SkillError
from teachfit.core.params import ParamDomain, ParamSpace

#: a literal number or a (possibly negated) parameter name
Value = float | str


def ref_name(value: Value) -> str | None:
    """The parameter a :data:`Value` refers to, or ``None`` for a literal."""
    if isinstance(value, bool):
        raise SkillError(f"a value must be a number or a parameter name, got {value!r}")
    if isinstance(value, int | float):
        return None
    if isinstance(value, str) and value.lstrip("-"):
        return value[1:] if value.startswith("-") else value
    raise SkillError(f"a value must be a number or a parameter name, got {value!r}")


def resolve(value: Value, values: Mapping[str, float]) -> float:
    """A :data:`Value` as a float, looking references up in ``values``."""
    name = ref_name(value)
    if name is None:
        return float(value)
    if name not in values:
        raise SkillError(f"unknown parameter {name!r}")
    v = float(values[name])
    return -v if isinstance(value, str) and value.startswith("-") else v


@dataclass(frozen=True)
class ContextParam:
    """A parameter the task context fixes (``value`` in ``unit``)."""

    value: float
    unit: str = ""
    doc: str = ""

    def __post_init__(self) -> None:
        if not math.isfinite(float(self.value)):
            raise SkillError(f"context value must be finite, got {self.value}")
        object.__setattr__(self, "value", float(self.value))


@dataclass(frozen=True)
class LearnedParam:
    """A parameter to learn: a ``default`` inside its ``domain`` (``unit``); ``bound`` says
    who narrowed the domain and how to widen it (empty: the skill's own domain)."""

    default: float
    domain: ParamDomain
    unit: str = ""
    doc: str = ""
    bound: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "default", float(self.default))


@dataclass(frozen=True)
class SkillParams:
    """The context and learned parameters of a skill (names unique across both)."""

    context: Mapping[str, ContextParam] = field(default_factory=dict)
    learned: Mapping[str, LearnedParam] = field(default_factory=dict)

    def __post_init__(self) -> None:
        ctx, lrn = dict(self.context), dict(self.learned)
        both = sorted(set(ctx) & set(lrn))
        if both:
            raise SkillError(f"parameter(s) {both} are both context and learned")
        for name in [*ctx, *lrn]:
            if not name.isidentifier():
                raise SkillError(f"parameter names must be identifiers, got {name!r}")
        object.__setattr__(self, "context", ctx)
        object.__setattr__(self, "learned", lrn)

    @property
    def names(self) -> set[str]:
        return set(self.context) | set(self.learned)

    @property
    def space(self) -> ParamSpace:
        """The learned parameters' domains, in declaration order."""
        return ParamSpace({n: p.domain for n, p in self.learned.items()})

    @property
    def defaults(self) -> dict[str, float]:
        """Default learned values."""
        return {n: p.default for n, p in self.learned.items()}

    def with_context(self, values: Mapping[str, float]) -> SkillParams:
        """A copy with context values replaced (unknown or learned names are errors)."""
        bad = sorted(set(values) - set(self.context))
        if bad:
            raise SkillError(f"unknown context parameter(s) {bad}; known: {sorted(self.context)}")
        ctx = {
            n: ContextParam(float(values[n]), p.unit, p.doc) if n in values else p
            for n, p in self.context.items()
        }
        return SkillParams(ctx, self.learned)

    def with_fixed(self, values: Mapping[str, float]) -> SkillParams:
        """A copy in which the learned parameters named in ``values`` are context parameters
        with those values (each inside its domain): a task that fixes them, as Johannsmeier et al.
        2019 fixes the key's initial tilt (Sec. V). Unknown names and values outside a domain are
        errors."""
        checked = self.check_learned(values)
        ctx = dict(self.context)
        for n in values:
            p = self.learned[n]
            ctx[n] = ContextParam(checked[n], p.unit, f"{p.doc} (fixed by the task, not learned)")
        lrn = {n: p for n, p in self.learned.items() if n not in values}
        return SkillParams(ctx, lrn)

    def with_domains(self, domains: Mapping[str, ParamDomain], why: str = "") -> SkillParams:
        """A copy in which the learned parameters named in ``domains`` search those domains
        instead (a task that bounds them tighter, as Johannsmeier et al. 2019 gives each task its
        own largest rotational amplitude, Sec. V); a default outside its new domain is clipped into
        it. ``why`` (who bounds them, how to widen) is added to an out-of-domain error. Unknown
        names are errors; names the task fixed are skipped (nothing left to bound)."""
        bad = sorted(n for n in domains if n not in self.learned and n not in self.context)
        if bad:
            raise SkillError(f"unknown learned parameter(s) {bad}; known: {list(self.learned)}")
        lrn = dict(self.learned)
        for n, dom in domains.items():
            if n in lrn:
                p = lrn[n]
                default = min(max(p.default, dom.low), dom.high)
                lrn[n] = LearnedParam(default, dom, p.unit, p.doc, why)
        return SkillParams(self.context, lrn)

    def check_learned(
        self, values: Mapping[str, float], users: Mapping[str, Iterable[str]] | None = None
    ) -> dict[str, float]:
        """Validated learned values: unknown names and values outside a domain are errors.

        Missing names take their defaults. ``users`` maps a parameter to the nodes using it,
        so that an out-of-domain error names them.
        """
        unknown = sorted(set(values) - set(self.learned))
        if unknown:
            ctx = [n for n in unknown if n in self.context]
            hint = f" ({ctx} are context parameters set by the task)" if ctx else ""
            raise SkillError(
                f"unknown learned parameter(s) {unknown}{hint}; known: {list(self.learned)}"
            )
        out = self.defaults
        for name, v in values.items():
            x = float(v)
            dom, bound = self.learned[name].domain, self.learned[name].bound
            if not (math.isfinite(x) and dom.contains(x)):
                nodes = sorted((users or {}).get(name, ()))
                where = f" (used by node(s) {nodes})" if nodes else ""
                where += f"; {bound}" if bound else ""
                raise SkillError(
                    f"parameter {name!r} = {x} is outside its domain [{dom.low:g}, {dom.high:g}]"
                    f"{where}",
                    node=nodes[0] if len(nodes) == 1 else None,
                )
            out[name] = x
        return out

    def all_values(self, learned: Mapping[str, float]) -> dict[str, float]:
        """Context values merged with (already validated) learned values."""
        out = {n: p.value for n, p in self.context.items()}
        out.update(learned)
        return out


def read_params_toml(
    path: str | Path, params: SkillParams, users: Mapping[str, Iterable[str]] | None = None
) -> dict[str, float]:
    """Learned values from a TOML file: a flat table or a ``[params]`` table.

    Every name must be a learned parameter of the skill and lie inside its domain; missing
    names keep their defaults. Errors name the file (and, given ``users`` -- e.g.
    ``Skill.users()`` -- the nodes using an out-of-domain parameter).
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise SkillError(f"cannot read parameter file {path}: {exc}") from exc
    data = data.get("params", data)
    bad = {k: v for k, v in data.items() if isinstance(v, bool) or not isinstance(v, int | float)}
    if bad:
        raise SkillError(f"{path}: parameter values must be numbers, got {bad}")
    try:
        return params.check_learned(data, users)
    except SkillError as exc:
        raise SkillError(f"{path}: {exc}") from exc


def write_params_toml(path: str | Path, params: Mapping[str, float], header: str = "") -> Path:
    """Learned values as a TOML ``[params]`` table that :func:`read_params_toml` reads back.

    ``header`` becomes ``#`` comment lines. The file is written atomically: to a temporary file
    in the same folder, then moved onto ``path`` (``os.replace``), so a reader sees the old file
    or the new one, never half of one; on failure the temporary file is removed.

    Raises
    ------
    SkillError
        A name that is not an identifier, a value that is not a finite number, or the file
        cannot be written.
    """
    path = Path(path)
    lines = [f"# {line}" for line in header.splitlines()] + ["[params]"]
    for name, v in params.items():
        if not name.isidentifier():
            raise SkillError(f"parameter names must be identifiers, got {name!r}")
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise SkillError(f"parameter {name!r} must be a finite number, got {v!r}")
        lines.append(f"{name} = {float(v)!r}")
    try:
        atomic_write_text(path, "\n".join(lines) + "\n", "parameter file")
    except OutputError as exc:
        raise SkillError(str(exc)) from exc
    return path
