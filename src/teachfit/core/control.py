"""Controller settings as data: which control law a robot runs, with its parameters.

A robot runs its 1 kHz loop itself (a real arm's firmware callback, the simulator's step), so
what the layers above hand it is data: a :data:`ControllerSpec`, either
:class:`FixedGainSpec` (Cartesian impedance with the gains each command carries, Ehlers et al. 2019
eqs. 8-9) or :class:`AdaptiveSpec` (Johannsmeier et al.'s adaptive impedance with its
meta-parameters). The laws themselves are in :mod:`teachfit.control`.

Also here: the meta-parameters of the adaptive impedance controller, the system limits, and the
bounds the limits imply on the meta-parameters (docs/methods.md, Johannsmeier et al. 2019).

All quantities are per task coordinate (x, y, z, rx, ry, rz; world frame at the TCP) and
stored as 6-tuples of floats so that the dataclasses are frozen, hashable and comparable.
See :mod:`teachfit.control.adaptive` for the control law they parameterise.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, fields
from typing import ClassVar

import numpy as np

from teachfit.core.errors import ControlError

Vec6 = tuple[float, float, float, float, float, float]


def vec6(values: Sequence[float] | np.ndarray) -> Vec6:
    """The six numbers of ``values`` (length 6, unchecked) as a tuple of floats."""
    a, b, c, d, e, f = (float(v) for v in values)
    return (a, b, c, d, e, f)


def _split6(linear: float, angular: float) -> Vec6:
    """``linear`` for x, y, z and ``angular`` for rx, ry, rz."""
    return (linear, linear, linear, angular, angular, angular)


@dataclass(frozen=True)
class ImpedanceLimits:
    """Safety limits of the impedance controller (N, N·m, m/s, rad/s)."""

    max_force: float = 60.0
    max_torque: float = 6.0
    max_speed: float = 0.25
    max_ang_speed: float = 1.5

    def __post_init__(self) -> None:
        for name in ("max_force", "max_torque", "max_speed", "max_ang_speed"):
            if not getattr(self, name) > 0:
                raise ControlError(f"{name} must be > 0, got {getattr(self, name)}")


def _six(value: float | Sequence[float] | np.ndarray, name: str, *, positive: bool) -> Vec6:
    arr = np.asarray(value, dtype=float)
    arr = np.full(6, float(arr)) if arr.ndim == 0 else arr.reshape(-1)
    if arr.shape != (6,):
        raise ControlError(f"{name} must be a scalar or 6 numbers, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ControlError(f"{name} contains NaN or inf")
    if positive and not np.all(arr > 0):
        raise ControlError(f"{name} must be > 0 per coordinate, got {arr.tolist()}")
    if not positive and not np.all(arr >= 0):
        raise ControlError(f"{name} must be >= 0 per coordinate, got {arr.tolist()}")
    return vec6(arr)


@dataclass(frozen=True)
class AdaptiveLimits:
    """System limits per task coordinate (x, y, z, rx, ry, rz).

    ``k_max`` stiffness (N/m, N·m/rad), ``dk_max`` stiffness rate (N/m/s, N·m/rad/s),
    ``f_max`` adaptive feed-forward (N, N·m), ``df_max`` its rate (N/s, N·m/s). Scalars are
    broadcast to all six coordinates. Defaults are of the order of a Franka Panda's.
    """

    k_max: Vec6 = _split6(3000.0, 300.0)
    dk_max: Vec6 = _split6(2.0e4, 2.0e3)
    f_max: Vec6 = _split6(20.0, 2.0)
    df_max: Vec6 = _split6(500.0, 50.0)

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, _six(getattr(self, f.name), f.name, positive=True))


@dataclass(frozen=True)
class AdaptiveParams:
    """Meta-parameters per task coordinate (all >= 0; scalars broadcast to six).

    ``alpha`` feed-forward learning rate (N per m/s per tick), ``beta`` stiffness learning rate
    (N/m per m²/s per tick), ``gamma_a`` (m/s per N) and ``gamma_b`` (m²/s per N/m) forgetting
    factors, ``kappa`` (1/s) weights the pose error in ``eps = de + kappa e`` (a design
    constant, not one of the four learned meta-parameters). Rotational coordinates use rad
    for m and N·m for N. The defaults lie within ``meta_bounds(AdaptiveLimits(), 1e-3,
    e_max=(0.01,)*3 + (0.1,)*3, de_max=(0.1,)*3 + (1.0,)*3)``.
    """

    alpha: Vec6 = _split6(0.5, 0.02)
    beta: Vec6 = _split6(2.0e3, 5.0)
    gamma_a: Vec6 = _split6(1.0e-4, 1.0e-2)
    gamma_b: Vec6 = _split6(5.0e-7, 1.0e-4)
    kappa: Vec6 = _split6(10.0, 10.0)

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, _six(getattr(self, f.name), f.name, positive=False))


@dataclass(frozen=True)
class MetaBounds:
    """Upper bounds of the meta-parameters (lower bounds are 0), per coordinate."""

    alpha: Vec6
    beta: Vec6
    gamma_a: Vec6
    gamma_b: Vec6

    def contains(self, params: AdaptiveParams) -> bool:
        """Whether every meta-parameter of ``params`` lies within ``[0, bound]``."""
        return all(
            np.all(np.asarray(getattr(params, n)) <= np.asarray(getattr(self, n)) * (1 + 1e-12))
            for n in ("alpha", "beta", "gamma_a", "gamma_b")
        )


def meta_bounds(
    limits: AdaptiveLimits,
    period: float,
    e_max: float | Sequence[float],
    de_max: float | Sequence[float],
    kappa: float | Sequence[float] = 10.0,
) -> MetaBounds:
    """Meta-parameter upper bounds implied by the system limits.

    With the largest tolerated errors ``e_max`` (m, rad), ``de_max`` (m/s, rad/s) and
    ``eps_max = de_max + kappa e_max``, one tick's learning step must fit within the rate
    limits, and forgetting must pull a saturated state back within them:

        alpha   <= dF_max T / eps_max            (|alpha eps| <= dF_max T)
        beta    <= dK_max T / (eps_max e_max)    (|beta eps e| <= dK_max T)
        gamma_a <= eps_max / F_max               (alpha_max gamma_a F_max <= dF_max T)
        gamma_b <= eps_max e_max / K_max         (beta_max gamma_b K_max <= dK_max T)

    The forgetting bounds also mean the largest tolerated error can sustain the saturated
    state (equilibria ``F_ff = eps/gamma_a``, ``K_a = eps e/gamma_b``).
    """
    if not period > 0:
        raise ControlError(f"period must be > 0 s, got {period}")
    e = np.asarray(_six(e_max, "e_max", positive=True))
    de = np.asarray(_six(de_max, "de_max", positive=False))
    eps = de + np.asarray(_six(kappa, "kappa", positive=True)) * e
    df = np.asarray(limits.df_max) * period
    dk = np.asarray(limits.dk_max) * period

    return MetaBounds(
        alpha=vec6(df / eps),
        beta=vec6(dk / (eps * e)),
        gamma_a=vec6(eps / np.asarray(limits.f_max)),
        gamma_b=vec6(eps * e / np.asarray(limits.k_max)),
    )


@dataclass(frozen=True)
class FixedGainSpec:
    """Fixed-gain Cartesian impedance: stiffness and damping come with each command."""

    kind: ClassVar[str] = "impedance"
    limits: ImpedanceLimits = field(default_factory=ImpedanceLimits)


@dataclass(frozen=True)
class AdaptiveSpec:
    """Johannsmeier et al.'s adaptive impedance: the command's stiffness is the floor, adapted on
    top.

    ``damping_ratio`` is ``xi`` of the adaptive damping term (``None``: each command's).
    """

    kind: ClassVar[str] = "adaptive"
    params: AdaptiveParams = field(default_factory=AdaptiveParams)
    limits: AdaptiveLimits = field(default_factory=AdaptiveLimits)
    impedance_limits: ImpedanceLimits = field(default_factory=ImpedanceLimits)
    damping_ratio: float | None = None

    def __post_init__(self) -> None:
        if self.damping_ratio is not None and not self.damping_ratio >= 0:
            raise ControlError(f"damping_ratio must be >= 0, got {self.damping_ratio}")


#: what a robot is told to run
ControllerSpec = FixedGainSpec | AdaptiveSpec
CONTROLLER_KINDS = ("adaptive", "impedance")
