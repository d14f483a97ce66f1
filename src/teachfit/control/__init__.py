"""Control laws a robot runs in its own loop: Cartesian impedance (Ehlers et al. 2019 eqs. 8-9) and
adaptive impedance (Johannsmeier et al. 2019), chosen by a
:data:`~teachfit.core.control.ControllerSpec`. Both laws are written once more, compiled, in
:mod:`teachfit.control.compiled`, which the simulated robots' kernels call."""

from __future__ import annotations

import numpy as np

from teachfit.control.adaptive import AdaptiveImpedance
from teachfit.control.base import Controller
from teachfit.control.impedance import CartesianImpedance, aligned_stiffness, critical_damping
from teachfit.core.control import AdaptiveSpec, ControllerSpec, FixedGainSpec
from teachfit.core.errors import ControlError


def make_law(spec: ControllerSpec, apparent_mass: np.ndarray, period: float) -> Controller:
    """The control law ``spec`` asks for, for a robot of ``apparent_mass`` (6,) (kg, kg·m²)
    ticking every ``period`` s."""
    if isinstance(spec, FixedGainSpec):
        return CartesianImpedance(apparent_mass, spec.limits)
    if isinstance(spec, AdaptiveSpec):
        return AdaptiveImpedance(
            apparent_mass,
            spec.params,
            spec.limits,
            spec.impedance_limits,
            period=period,
            damping_ratio=spec.damping_ratio,
        )
    raise ControlError(f"unknown controller spec {spec!r}")


__all__ = [
    "AdaptiveImpedance",
    "CartesianImpedance",
    "Controller",
    "aligned_stiffness",
    "critical_damping",
    "make_law",
]
