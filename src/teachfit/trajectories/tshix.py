"""TSHIX: Trajectory Sampling from Human-Inspired eXploration, and the SearchTrajectory type.

One pass: draw N samples from p_e, find the shortest open tour through them from the
search-frame origin (:mod:`teachfit.trajectories.tsp`), resample that polyline densely at a fixed
arc-length spacing, smooth it with a Savitzky-Golay filter and time it at the teacher's speed.
After a failed pass :meth:`TshixPlanner.extend` samples new points and continues from where the
previous pass ended instead of repeating it.

Metric: a rotation about z counts as ``ℓ`` metres per radian (``length_scale``), i.e. the
weighted state is ``(x, y, ℓ rz)``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, cast

import numpy as np
from scipy.signal import savgol_filter

from teachfit.core.errors import ModelError, PlanningError
from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.tsp import open_tour


@dataclass(frozen=True)
class SearchTrajectory:
    """A timed search trajectory in the search frame.

    Attributes
    ----------
    t : ndarray, shape (T,)
        Strictly increasing times, s.
    states : ndarray, shape (T, D)
        Search states (m, rad) in the search frame.
    dims : tuple of str
        DOF names (D).
    method : str
        Generator ("tshix", "ergodic", "spiral", "random_walk").
    samples : ndarray, shape (N, D), optional
        Raw samples drawn from p_e (TSHIX), in drawing order.
    order : ndarray of int, shape (N,), optional
        Visiting order of ``samples`` (the itinerary is ``start, samples[order]``).
    start : ndarray, shape (D,), optional
        First itinerary point (the origin for a first pass).
    meta : mapping
        Generator parameters and figures of merit (e.g. ``ergodic_metric``).
    """

    t: np.ndarray
    states: np.ndarray
    dims: tuple[str, ...]
    method: str = ""
    samples: np.ndarray | None = None
    order: np.ndarray | None = None
    start: np.ndarray | None = None
    meta: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        t = np.asarray(self.t, dtype=float)
        s = np.asarray(self.states, dtype=float)
        if t.ndim != 1 or s.shape != (t.size, len(self.dims)) or t.size < 2:
            raise PlanningError(f"need t (T,) and states (T, {len(self.dims)}), T >= 2")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(s))) or np.any(np.diff(t) <= 0):
            raise PlanningError("trajectory must be finite with strictly increasing times")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "states", s)
        object.__setattr__(self, "dims", tuple(self.dims))

    @property
    def duration(self) -> float:
        """t[-1] - t[0], s."""
        return float(self.t[-1] - self.t[0])

    @property
    def itinerary(self) -> np.ndarray | None:
        """``start, samples[order]`` (N + 1, D), or None without samples."""
        if self.samples is None or self.order is None or self.start is None:
            return None
        return np.vstack([self.start[None], self.samples[self.order]])

    def path_length(self, length_scale: float = 1.0) -> float:
        """Arc length with rz weighted by ``length_scale`` (m / rad)."""
        w = metric_weights(self.dims, length_scale)
        return float(np.linalg.norm(np.diff(self.states * w, axis=0), axis=1).sum())


def metric_weights(dims: Sequence[str], length_scale: float) -> np.ndarray:
    """Per-DOF metric scale: 1 for lengths, ``length_scale`` (m / rad) for rz."""
    return np.array([length_scale if d == "rz" else 1.0 for d in dims])


def default_length_scale(exploration: ExplorationDistribution) -> float:
    """ℓ (m / rad) that makes rz as wide as the linear DOFs: ``sqrt(mean σ²_lin / σ²_rz)``."""
    if "rz" not in exploration.dims:
        return 1.0
    var = np.diag(exploration.cov)
    i = exploration.dims.index("rz")
    lin = [var[k] for k, d in enumerate(exploration.dims) if d != "rz"]
    return float(np.sqrt(np.mean(lin) / var[i])) if lin else 1.0


def timed_path(
    path: np.ndarray,
    dims: Sequence[str],
    *,
    speed: float,
    angular_speed: float | None = None,
    length_scale: float = 1.0,
    rate_hz: float = 100.0,
    t0: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Time a polyline and sample it uniformly at ``rate_hz``.

    Each segment Δ takes ``max(‖Δ_lin‖ / speed, |Δ_rz| / angular_speed)`` seconds when an angular
    speed is given, else ``‖diag(w) Δ‖ / speed`` with w from :func:`metric_weights`. Returns
    ``(t (T,), states (T, D))`` starting at ``t0``; states are linear in time on each segment.
    """
    path = np.asarray(path, dtype=float)
    if not (np.isfinite(speed) and speed > 0) or rate_hz <= 0:
        raise PlanningError(f"speed and rate must be positive, got {speed}, {rate_hz}")
    if angular_speed is not None and not angular_speed > 0:
        raise PlanningError(f"angular speed must be positive, got {angular_speed}")
    dims = tuple(dims)
    delta = np.diff(path, axis=0)
    if angular_speed is not None and "rz" in dims:
        lin = [k for k, d in enumerate(dims) if d != "rz"]
        dt = np.maximum(
            np.linalg.norm(delta[:, lin], axis=1) / speed,
            np.abs(delta[:, dims.index("rz")]) / angular_speed,
        )
    else:
        dt = np.linalg.norm(delta * metric_weights(dims, length_scale), axis=1) / speed
    keep = np.concatenate([[True], dt > 1e-12])
    path, tk = path[keep], np.concatenate([[0.0], np.cumsum(dt[dt > 1e-12])])
    if path.shape[0] < 2:
        raise PlanningError("path has zero length")
    grid = np.arange(0.0, tk[-1], 1.0 / rate_hz)
    if tk[-1] - grid[-1] > 1e-9:
        grid = np.append(grid, tk[-1])
    states = np.stack([np.interp(grid, tk, c) for c in path.T], axis=1)
    return grid + t0, states


def _smooth(path: np.ndarray, window: int, polyorder: int) -> np.ndarray:
    """Savitzky-Golay smoothing that keeps both end points exactly.

    The path is extended by point reflection about each end (``2 p_0 - p_k``); a symmetric
    filter maps a point-symmetric signal to its centre value, so the ends are unchanged.
    """
    m = path.shape[0]
    window = min(window, m - 1 if m % 2 == 0 else m)
    if window <= polyorder + 1:
        return path
    h = window
    head = 2 * path[0] - path[h:0:-1]
    tail = 2 * path[-1] - path[-2 : -h - 2 : -1]
    ext = np.vstack([head, path, tail])
    return savgol_filter(ext, window, polyorder, axis=0, mode="interp")[h : h + m]


@dataclass(frozen=True)
class TshixPlanner:
    """TSHIX trajectory generator.

    Parameters
    ----------
    exploration : ExplorationDistribution
        p_e in the search frame.
    speed : float
        Teacher's speed in the search plane, m/s.
    angular_speed : float, optional
        Teacher's rz speed, rad/s (timing uses the slower of both constraints per segment).
    length_scale : float, optional
        ℓ in m / rad for rz in the TSP metric and smoothing; default :func:`default_length_scale`.
    rate_hz : float
        Output sample rate, Hz.
    smooth : float
        Savitzky-Golay window as a multiple of the median itinerary edge length.
    polyorder : int
        Savitzky-Golay polynomial order.
    points_per_edge : int
        Dense resampling: median edge length / spacing.
    solver : {"fast", "lkh"}
        TSP solver.
    sampling : {"qmc", "random"}
        ``"random"``: i.i.d. draws from p_e (Ehlers et al. 2019). ``"qmc"`` (default): scrambled
        Sobol points through p_e's inverse CDF, equally distributed but more even, so the tour
        leaves fewer gaps (measured in BENCHMARKS.md, Table I).
    """

    exploration: ExplorationDistribution
    speed: float
    angular_speed: float | None = None
    length_scale: float | None = None
    rate_hz: float = 100.0
    smooth: float = 1.5
    polyorder: int = 3
    points_per_edge: int = 8
    solver: Literal["fast", "lkh"] = "fast"
    sampling: Literal["qmc", "random"] = "qmc"

    def __post_init__(self) -> None:
        if not (np.isfinite(self.speed) and self.speed > 0):
            raise ModelError(f"speed must be positive, got {self.speed}")
        if self.sampling not in ("qmc", "random"):
            raise ModelError(f"sampling must be 'qmc' or 'random', got {self.sampling!r}")
        if self.length_scale is None:
            object.__setattr__(self, "length_scale", default_length_scale(self.exploration))
        if not self._length_scale > 0 or self.rate_hz <= 0 or self.smooth < 0:
            raise ModelError("length_scale and rate_hz must be positive, smooth >= 0")

    @property
    def _length_scale(self) -> float:
        """``length_scale``, never None after ``__post_init__`` (which sets the default)."""
        return cast(float, self.length_scale)

    @classmethod
    def from_model(cls, model: Any, **kwargs: Any) -> TshixPlanner:
        """Planner with the exploration and teacher speeds of a :class:`SearchModel`."""
        return cls(model.exploration, model.speed, model.angular_speed, **kwargs)

    def _pass(
        self, n: int, rng: np.random.Generator, start: np.ndarray, t0: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        if not isinstance(n, int | np.integer) or n <= 0:
            raise PlanningError(f"number of samples must be a positive integer, got {n!r}")
        dims = self.exploration.dims
        w = metric_weights(dims, self._length_scale)
        samples = self.exploration.sample(int(n), rng, qmc=self.sampling == "qmc")
        tour = open_tour(samples, start, weights=w, solver=self.solver, rng=rng)
        poly = np.vstack([start[None], samples[tour.order]]) * w
        seg = np.linalg.norm(np.diff(poly, axis=0), axis=1)
        if seg.sum() <= 0:
            raise PlanningError("all samples coincide with the start")
        h = float(np.median(seg[seg > 0])) / self.points_per_edge
        arc = np.concatenate([[0.0], np.cumsum(seg)])
        s = np.linspace(0.0, arc[-1], max(int(np.ceil(arc[-1] / h)) + 1, 2))
        dense = np.stack([np.interp(s, arc, c) for c in poly.T], axis=1)
        window = int(round(self.smooth * self.points_per_edge)) | 1
        smooth = _smooth(dense, window, self.polyorder) / w
        t, states = timed_path(
            smooth,
            dims,
            speed=self.speed,
            angular_speed=self.angular_speed,
            length_scale=self._length_scale,
            rate_hz=self.rate_hz,
            t0=t0,
        )
        return t, states, samples, tour.order

    def plan(
        self, n: int, rng: np.random.Generator, start: np.ndarray | None = None
    ) -> SearchTrajectory:
        """One TSHIX pass through ``n`` samples from ``start`` (default: the origin)."""
        s0 = np.zeros(self.exploration.dim) if start is None else np.asarray(start, float)
        t, states, samples, order = self._pass(n, rng, s0, 0.0)
        return SearchTrajectory(
            t,
            states,
            self.exploration.dims,
            "tshix",
            samples,
            order,
            s0,
            {"n_samples": int(n), "passes": 1, "length_scale": self.length_scale},
        )

    def extend(self, traj: SearchTrajectory, n: int, rng: np.random.Generator) -> SearchTrajectory:
        """Append a new pass of ``n`` fresh samples starting where ``traj`` ends."""
        if traj.dims != self.exploration.dims:
            raise PlanningError(
                f"trajectory dims {traj.dims} != planner dims {self.exploration.dims}"
            )
        t, states, samples, order = self._pass(n, rng, traj.states[-1], float(traj.t[-1]))
        old_n = 0 if traj.samples is None else traj.samples.shape[0]
        all_samples = samples if traj.samples is None else np.vstack([traj.samples, samples])
        all_order = (
            order + old_n if traj.order is None else np.concatenate([traj.order, order + old_n])
        )
        meta = dict(traj.meta)
        meta["n_samples"] = int(meta.get("n_samples", 0)) + int(n)
        meta["passes"] = int(meta.get("passes", 1)) + 1
        return SearchTrajectory(
            np.concatenate([traj.t, t[1:]]),
            np.vstack([traj.states, states[1:]]),
            traj.dims,
            traj.method or "tshix",
            all_samples,
            all_order,
            traj.start,
            meta,
        )


def tshix(
    exploration: ExplorationDistribution,
    n: int,
    rng: np.random.Generator,
    *,
    speed: float,
    angular_speed: float | None = None,
    **kwargs: Any,
) -> SearchTrajectory:
    """One TSHIX pass from the origin; keyword arguments as for :class:`TshixPlanner`."""
    return TshixPlanner(exploration, speed, angular_speed, **kwargs).plan(n, rng)
