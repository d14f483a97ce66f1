"""The controller a skill runs on, and the adaptive controller's meta-parameters as learned
skill parameters.

Johannsmeier et al. 2019 learns the adaptive impedance controller's meta-parameters together with
the skill's own. Per coordinate group ``g`` in ``t`` (x, y, z) and ``r`` (rx, ry, rz) they are
``alpha_g``, ``beta_g``, ``gamma_a_g``, ``gamma_b_g`` (see
:mod:`teachfit.control.adaptive`), each in a log domain ``[bound * 1e-3, bound]`` whose upper
bound follows from the system limits by
:func:`~teachfit.control.adaptive_params.meta_bounds` (largest tolerated errors 10 mm /
0.1 m/s and 0.1 rad / 1 rad/s, control period 1 ms). The fixed-gain controller has none.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from teachfit.core.control import (
    AdaptiveLimits,
    AdaptiveParams,
    AdaptiveSpec,
    ControllerSpec,
    FixedGainSpec,
    meta_bounds,
)
from teachfit.core.errors import SkillError
from teachfit.core.params import ParamDomain
from teachfit.skills.params import LearnedParam

CONTROLLERS = ("adaptive", "impedance")
_META = ("alpha", "beta", "gamma_a", "gamma_b")
#: units per meta-parameter and group: t (translation: N, m) and r (rotation: N·m, rad)
_UNITS = {
    ("alpha", "t"): "N/(m/s)/tick",
    ("beta", "t"): "N/m/(m²/s)/tick",
    ("gamma_a", "t"): "(m/s)/N",
    ("gamma_b", "t"): "(m²/s)/(N/m)",
    ("alpha", "r"): "N·m/(rad/s)/tick",
    ("beta", "r"): "N·m/rad/(rad²/s)/tick",
    ("gamma_a", "r"): "(rad/s)/(N·m)",
    ("gamma_b", "r"): "(rad²/s)/(N·m/rad)",
}
#: largest tolerated errors behind the meta-parameter bounds (translation, rotation)
E_MAX = (0.01,) * 3 + (0.1,) * 3
DE_MAX = (0.1,) * 3 + (1.0,) * 3


def controller_params(kind: str, period: float = 0.001) -> dict[str, LearnedParam]:
    """The learned controller parameters of ``kind`` (empty for ``"impedance"``)."""
    if kind not in CONTROLLERS:
        raise SkillError(f"unknown controller {kind!r}; known: {list(CONTROLLERS)}")
    if kind == "impedance":
        return {}
    bounds = meta_bounds(AdaptiveLimits(), period, E_MAX, DE_MAX)
    defaults = AdaptiveParams()
    out = {}
    for meta in _META:
        hi, default = getattr(bounds, meta), getattr(defaults, meta)
        for g, i in (("t", 0), ("r", 3)):
            dom = ParamDomain(hi[i] * 1e-3, hi[i], log=True)
            val = float(np.clip(default[i], dom.low, dom.high))
            out[f"{meta}_{g}"] = LearnedParam(
                val, dom, _UNITS[meta, g], f"adaptive controller {meta}, group {g}"
            )
    return out


def controller_spec(kind: str, values: Mapping[str, float]) -> ControllerSpec:
    """The controller settings (data for the robot) of ``kind``; ``values`` supplies the
    adaptive meta-parameters (those it lacks, e.g. for a skill that does not learn them, keep
    :class:`AdaptiveParams`' defaults)."""
    if kind == "impedance":
        return FixedGainSpec()
    if kind != "adaptive":
        raise SkillError(f"unknown controller {kind!r}; known: {list(CONTROLLERS)}")
    defaults = AdaptiveParams()
    kwargs = {}
    for meta in _META:
        d = getattr(defaults, meta)
        t = float(values.get(f"{meta}_t", d[0]))
        r = float(values.get(f"{meta}_r", d[3]))
        kwargs[meta] = (t,) * 3 + (r,) * 3
    return AdaptiveSpec(params=AdaptiveParams(**kwargs))
