"""Named, box-bounded parameter domains: what skills declare and learners search.

A :class:`ParamSpace` names the learned parameters and their :class:`ParamDomain`
``[low, high]`` in physical units. Learners search the unit cube ``u in [0, 1]^d``:

    x_i = low_i + u_i (high_i - low_i)                       (linear domain)
    x_i = exp(log low_i + u_i (log high_i - log low_i))      (``log=True``, low_i > 0)

so that one step size means the same for every parameter.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from teachfit.core.errors import TeachfitError


class LearningError(TeachfitError):
    """Invalid learning set-up: parameter space, values outside it, learner options, studies."""


@dataclass(frozen=True)
class ParamDomain:
    """The closed interval ``[low, high]`` a learned parameter lives in (physical units).

    ``log=True`` searches it on a logarithmic scale (needs ``low > 0``).
    """

    low: float
    high: float
    log: bool = False

    def __post_init__(self) -> None:
        low, high = float(self.low), float(self.high)
        if not (math.isfinite(low) and math.isfinite(high)) or not low < high:
            raise LearningError(f"a domain needs finite low < high, got [{self.low}, {self.high}]")
        if self.log and not low > 0:
            raise LearningError(f"a log domain needs low > 0, got {low}")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)

    def contains(self, value: float) -> bool:
        return self.low <= value <= self.high

    def to_unit(self, value: float) -> float:
        if self.log:
            lo, hi = math.log(self.low), math.log(self.high)
            return (math.log(value) - lo) / (hi - lo)
        return (value - self.low) / (self.high - self.low)

    def from_unit(self, u: float) -> float:
        u = min(max(float(u), 0.0), 1.0)
        if self.log:
            lo, hi = math.log(self.low), math.log(self.high)
            return min(max(math.exp(lo + u * (hi - lo)), self.low), self.high)
        return self.low + u * (self.high - self.low)


@dataclass(frozen=True)
class ParamSpace:
    """Named parameter domains, in a fixed order (the order of the unit-cube coordinates)."""

    domains: Mapping[str, ParamDomain]

    def __post_init__(self) -> None:
        doms = dict(self.domains)
        if not doms:
            raise LearningError("a parameter space needs at least one parameter")
        for name, dom in doms.items():
            if not isinstance(name, str) or not name:
                raise LearningError(f"parameter names must be non-empty strings, got {name!r}")
            if not isinstance(dom, ParamDomain):
                raise LearningError(f"parameter {name!r}: domain must be a ParamDomain")
        object.__setattr__(self, "domains", doms)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.domains)

    @property
    def dim(self) -> int:
        return len(self.domains)

    def __iter__(self) -> Iterator[str]:
        return iter(self.domains)

    def validate(self, values: Mapping[str, float]) -> dict[str, float]:
        """``values`` as floats, checked: every name known, present, inside its domain."""
        unknown = sorted(set(values) - set(self.domains))
        if unknown:
            raise LearningError(f"unknown parameter(s) {unknown}; known: {list(self.names)}")
        missing = [n for n in self.names if n not in values]
        if missing:
            raise LearningError(f"missing parameter(s) {missing}")
        out = {}
        for name, dom in self.domains.items():
            v = float(values[name])
            if not dom.contains(v):
                raise LearningError(f"parameter {name!r} = {v} outside [{dom.low}, {dom.high}]")
            out[name] = v
        return out

    def to_unit(self, values: Mapping[str, float]) -> np.ndarray:
        """Physical values -> unit-cube point (d,) (validated)."""
        vals = self.validate(values)
        return np.array([dom.to_unit(vals[n]) for n, dom in self.domains.items()])

    def from_unit(self, u: Sequence[float] | np.ndarray) -> dict[str, float]:
        """Unit-cube point (d,) -> physical values (clipped into the domains)."""
        arr = np.asarray(u, dtype=float).reshape(-1)
        if arr.shape != (self.dim,):
            raise LearningError(f"expected a point of {self.dim} coordinates, got {arr.shape}")
        return {n: dom.from_unit(x) for (n, dom), x in zip(self.domains.items(), arr, strict=True)}

    def to_json(self) -> dict[str, Any]:
        """A JSON-able description (stored with a study, compared on resume)."""
        return {n: [d.low, d.high, d.log] for n, d in self.domains.items()}

    @classmethod
    def from_json(cls, data: Mapping[str, Sequence[Any]]) -> ParamSpace:
        return cls({n: ParamDomain(float(v[0]), float(v[1]), bool(v[2])) for n, v in data.items()})
