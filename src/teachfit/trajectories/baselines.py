"""Baseline search trajectories: random walk (Abu-Dakka et al.), Archimedean spiral (Jasim et al.).

Both are blind to the demonstrations apart from their size parameters and return a
:class:`SearchTrajectory` in the search frame starting at ``start`` (default the origin).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from teachfit.core.errors import PlanningError
from teachfit.trajectories.tshix import SearchTrajectory, timed_path


def _check_dims(dims: Sequence[str]) -> tuple[str, ...]:
    dims = tuple(dims)
    if dims not in (("x", "y"), ("x", "y", "rz")):
        raise PlanningError(f"baselines support dims (x, y) or (x, y, rz), got {dims}")
    return dims


def random_walk(
    dims: Sequence[str],
    rng: np.random.Generator,
    *,
    n_steps: int,
    step_max: float,
    radius: float,
    speed: float,
    step_min: float | None = None,
    rz_step_max: float = 0.0,
    rz_radius: float = 0.0,
    angular_speed: float | None = None,
    length_scale: float = 1.0,
    start: np.ndarray | None = None,
    rate_hz: float = 100.0,
) -> SearchTrajectory:
    """Random-walk search: straight moves in uniformly random directions.

    Each move has length ``U(step_min, step_max)`` (m; default ``step_min = step_max / 2``) and,
    for D = 3, an rz change ``U(-rz_step_max, rz_step_max)`` (rad). A move that would leave the
    disc of ``radius`` around ``start`` (or ``|rz - rz_0| > rz_radius``) is redrawn (up to 50
    times), else reflected back towards the centre. Waypoints are joined by straight segments
    timed at ``speed`` (see :func:`timed_path`).
    """
    dims = _check_dims(dims)
    if n_steps <= 0 or step_max <= 0 or radius <= 0:
        raise PlanningError("n_steps, step_max and radius must be positive")
    lo = 0.5 * step_max if step_min is None else float(step_min)
    if not 0 <= lo <= step_max:
        raise PlanningError("need 0 <= step_min <= step_max")
    d = len(dims)
    s0 = np.zeros(d) if start is None else np.asarray(start, float)
    walk = _Walk(s0, rng, lo, step_max, radius, rz_step_max, rz_radius)
    pts = [s0.copy()] + [p for _ in range(int(n_steps)) if (p := walk.move()) is not None]
    if len(pts) < 2:
        raise PlanningError("random walk did not move")
    t, states = timed_path(
        np.array(pts),
        dims,
        speed=speed,
        angular_speed=angular_speed,
        length_scale=length_scale,
        rate_hz=rate_hz,
    )
    return SearchTrajectory(
        t,
        states,
        dims,
        "random_walk",
        start=s0,
        meta={"n_steps": int(n_steps), "radius": radius, "step_max": step_max},
    )


class _Walk:
    """The random walk's waypoints: each :meth:`move` from the current one (see
    :func:`random_walk`)."""

    def __init__(
        self,
        s0: np.ndarray,
        rng: np.random.Generator,
        lo: float,
        step_max: float,
        radius: float,
        rz_step_max: float,
        rz_radius: float,
    ) -> None:
        self.s0, self.cur, self.rng = s0, s0.copy(), rng
        self.lo, self.step_max, self.radius = lo, step_max, radius
        self.rz_step_max, self.rz_radius = rz_step_max, rz_radius

    def _draw(self) -> np.ndarray | None:
        """A move inside the disc (and the rz band), redrawn up to 50 times; None if none."""
        cur, s0, d = self.cur, self.s0, self.s0.size
        for _try in range(50):
            ang = self.rng.uniform(0.0, 2.0 * np.pi)
            step = self.rng.uniform(self.lo, self.step_max)
            nxt = cur.copy()
            nxt[:2] += step * np.array([np.cos(ang), np.sin(ang)])
            if d == 3:
                nxt[2] += self.rng.uniform(-self.rz_step_max, self.rz_step_max)
            ok = np.linalg.norm(nxt[:2] - s0[:2]) <= self.radius
            if d == 3:
                ok = ok and abs(nxt[2] - s0[2]) <= self.rz_radius + 1e-15
            if ok:
                return nxt
        return None

    def move(self) -> np.ndarray | None:
        """The next waypoint (reflected towards the centre when no draw fits), or None when
        it did not move."""
        cur, nxt = self.cur, self._draw()
        if nxt is None:  # reflect: head for the centre instead
            to_c = self.s0 - cur
            nxt = cur + to_c * min(1.0, self.step_max / max(float(np.linalg.norm(to_c[:2])), 1e-15))
        if not np.linalg.norm(nxt - cur) > 0:
            return None
        self.cur = nxt
        return nxt


def archimedean_spiral(
    dims: Sequence[str],
    *,
    pitch: float,
    radius: float,
    speed: float,
    rz_amplitude: float = 0.0,
    rz_turns_per_sweep: float = 1.0,
    angular_speed: float | None = None,
    length_scale: float = 1.0,
    start: np.ndarray | None = None,
    rate_hz: float = 100.0,
) -> SearchTrajectory:
    """Archimedean spiral ``r = a θ`` with ``a = pitch / (2π)`` out to ``radius``.

    ``pitch`` (m) is the distance between turns, about the capture width of the hole. For
    D = 3, rz stays at ``start``'s value or, with ``rz_amplitude`` > 0, sweeps
    ``rz_amplitude · sin(θ / rz_turns_per_sweep)`` (rad). Timed at constant ``speed`` along the
    path (weighted with ``length_scale`` for rz, or also limited by ``angular_speed``).
    """
    dims = _check_dims(dims)
    if pitch <= 0 or radius <= 0 or radius < pitch / 4:
        raise PlanningError("need pitch > 0 and radius >= pitch / 4")
    d = len(dims)
    s0 = np.zeros(d) if start is None else np.asarray(start, float)
    a = pitch / (2.0 * np.pi)
    theta_max = radius / a
    # dense θ grid, then resample uniformly in arc length s(θ) = a/2 (θ √(1+θ²) + asinh θ)
    theta = np.linspace(0.0, theta_max, int(np.ceil(theta_max * 200)) + 2)
    arc = 0.5 * a * (theta * np.sqrt(1.0 + theta**2) + np.arcsinh(theta))
    n = int(np.ceil(arc[-1] / (pitch / 50.0))) + 2
    theta = np.interp(np.linspace(0.0, arc[-1], n), arc, theta)
    r = a * theta
    path = np.zeros((n, d))
    path[:, 0], path[:, 1] = r * np.cos(theta), r * np.sin(theta)
    if d == 3 and rz_amplitude > 0:
        path[:, 2] = rz_amplitude * np.sin(theta / rz_turns_per_sweep)
    path += s0
    t, states = timed_path(
        path,
        dims,
        speed=speed,
        angular_speed=angular_speed,
        length_scale=length_scale,
        rate_hz=rate_hz,
    )
    return SearchTrajectory(
        t,
        states,
        dims,
        "spiral",
        start=s0,
        meta={"pitch": pitch, "radius": radius, "rz_amplitude": rz_amplitude},
    )
