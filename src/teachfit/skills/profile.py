"""Trapezoidal velocity profile: the time scaling of point-to-point primitives.

A path of length ``d`` is travelled with speed ramping up at ``a`` to at most ``v``, cruising,
and ramping down at ``a``. With ``t_a = v / a``:

* ``d >= v t_a`` (trapezoid): ``T = d / v + t_a``;
* otherwise (triangle, ``v`` never reached): ``t_a = sqrt(d / a)``, ``T = 2 t_a``.

The position is ``s(t) = a t^2 / 2`` while accelerating, ``s(t_a) + v_p (t - t_a)`` cruising
and symmetric while braking (``v_p`` the peak speed). Units are whatever ``d`` has (m or rad).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from teachfit.core.errors import SkillError


@dataclass(frozen=True)
class Trapezoid:
    """A trapezoidal profile over ``distance`` (>= 0) with limits ``v_max``, ``a_max`` (> 0)."""

    distance: float
    v_max: float
    a_max: float

    def __post_init__(self) -> None:
        if not (self.v_max > 0 and self.a_max > 0):
            raise SkillError(f"profile limits must be > 0, got v={self.v_max}, a={self.a_max}")
        if not self.distance >= 0 or not math.isfinite(self.distance):
            raise SkillError(f"profile distance must be finite and >= 0, got {self.distance}")

    @property
    def t_acc(self) -> float:
        """Duration of the acceleration (and of the braking) phase (s)."""
        if self.distance >= self.v_max**2 / self.a_max:
            return self.v_max / self.a_max
        return math.sqrt(self.distance / self.a_max)

    @property
    def v_peak(self) -> float:
        return self.a_max * self.t_acc

    @property
    def duration(self) -> float:
        ta = self.t_acc
        if ta == 0.0:
            return 0.0
        return self.distance / self.v_peak + ta

    def position(self, t: float) -> float:
        """Distance travelled at time ``t`` (clamped to ``[0, distance]``)."""
        T, ta, a = self.duration, self.t_acc, self.a_max
        if t <= 0.0 or T == 0.0:
            return 0.0
        if t >= T:
            return self.distance
        if t < ta:
            return 0.5 * a * t * t
        if t <= T - ta:
            return 0.5 * a * ta * ta + self.v_peak * (t - ta)
        r = T - t
        return self.distance - 0.5 * a * r * r

    def velocity(self, t: float) -> float:
        """Speed at time ``t``."""
        T, ta = self.duration, self.t_acc
        if t <= 0.0 or t >= T:
            return 0.0
        if t < ta:
            return self.a_max * t
        if t <= T - ta:
            return self.v_peak
        return self.a_max * (T - t)


def synchronized(
    distances: tuple[float, ...], v_max: tuple[float, ...], a_max: tuple[float, ...]
) -> Trapezoid:
    """A unit-length profile (``s`` from 0 to 1) moving several coordinates in step.

    Coordinate ``i`` travels ``distances[i] * s(t)``; the unit profile's limits are the
    tightest ``v_max[i] / d_i`` and ``a_max[i] / d_i``, so every coordinate keeps its own
    limits and all arrive together.
    """
    v, a = math.inf, math.inf
    for d, vi, ai in zip(distances, v_max, a_max, strict=True):
        if d > 0:
            v, a = min(v, vi / d), min(a, ai / d)
    if math.isinf(v):
        return Trapezoid(0.0, 1.0, 1.0)
    return Trapezoid(1.0, v, a)
