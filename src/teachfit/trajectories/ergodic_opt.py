"""Ergodic trajectory optimisation (Miller & Murphey's objective, single-integrator dynamics).

Miller & Murphey optimise a trajectory x(t) for the cost

    J(x, u) = q E(x) + 1/2 ∫ u(t)ᵀ R u(t) dt,      ẋ = u,  x(0) = x_0,

with E the ergodic metric Σ_k Λ_k (c_k(x) - φ_k)² (see :mod:`teachfit.trajectories.ergodic`),
by projection-based trajectory optimisation: a descent direction is computed for the
unconstrained pair (x, u) and projected back onto the dynamics. For the single integrator
ẋ = u used here (the search is kinematic; the impedance controller tracks it) the projection
is the integral x = x_0 + ∫ u, so optimising the waypoints of a fixed-time, uniformly sampled
trajectory directly is the same problem. We descend with L-BFGS (:func:`scipy.optimize.minimize`)
on the analytical gradient of E:

    ∂c_k / ∂u_{t,i} = w_t (-π k_i sin(π k_i u_{t,i})) Π_{j≠i} cos(π k_j u_{t,j}) / h_k,

u being the state scaled to the unit box and w_t the time weights. Written here because no
maintained library offers ergodic trajectory optimisation; the spectral coverage start
(:func:`~teachfit.trajectories.ergodic.ergodic_trajectory`) is the initial guess.
"""

from __future__ import annotations

import importlib
from dataclasses import replace

import numpy as np
from scipy.optimize import minimize

from teachfit.core.errors import PlanningError
from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.ergodic import (
    CosineBasis,
    _default_coeffs,
    _requested_length,
    ergodic_metric,
    ergodic_trajectory,
    search_box,
)
from teachfit.trajectories.tshix import SearchTrajectory, metric_weights, timed_path


def _cos_sin(basis: CosineBasis, u: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
    kk = np.arange(basis.n_coeffs)
    arg = [np.pi * u[:, [i]] * kk for i in range(basis.dim)]
    return [np.cos(a) for a in arg], [-np.pi * kk * np.sin(a) for a in arg]


#: BLAS thread limits (threadpoolctl comes with scikit-learn; it ships no type information)
threadpool_limits = importlib.import_module("threadpoolctl").threadpool_limits

#: with ``keep_length``, steps aim this much beyond the asked length, the timed path is cut
_AIM = 1.02
#: ... and the speed term weighs this much more than in the free optimisation
_HOLD = 10.0


def _options(iterations: int) -> dict[str, float]:
    """L-BFGS-B's options: ``iterations`` and tolerances that let it use them (the metric
    is small, 1e-4 ... 1e-2: the default tolerances stop it after 10-20 steps)."""
    return {"maxiter": int(iterations), "ftol": 1e-15, "gtol": 1e-12}


def ergodic_cost_and_gradient(
    states: np.ndarray, basis: CosineBasis, phi: np.ndarray, weights: np.ndarray | None = None
) -> tuple[float, np.ndarray]:
    """E and dE/dstates (T, D) for a trajectory sampled uniformly in time (or with ``weights``).

    ``weights`` (T,) sum to 1 (default uniform). D = 2 or 3.
    """
    s = np.asarray(states, float)
    t_n, d = s.shape
    if d not in (2, 3):
        raise PlanningError("ergodic optimisation needs D = 2 or 3")
    w = np.full(t_n, 1.0 / t_n) if weights is None else np.asarray(weights, float)
    size = basis.hi - basis.lo
    cs, ds = _cos_sin(basis, basis.to_unit(s))
    k = basis.n_coeffs
    # the product of the other dimensions' cosines, (T, K^(D-1)): matrix products, no einsum
    rest = cs[1] if d == 2 else (cs[1][:, :, None] * cs[2][:, None, :]).reshape(t_n, k * k)
    c = ((cs[0] * w[:, None]).T @ rest).reshape(basis.weights.shape) / basis.norm
    diff = c - phi
    e = float(np.sum(basis.weights * diff**2))
    g = (2.0 * basis.weights * diff / basis.norm).reshape(k, -1)  # dE/dc_k / h_k
    grad = np.empty_like(s)
    grad[:, 0] = np.sum((ds[0] @ g) * rest, axis=1)
    gt = cs[0] @ g  # (T, K^(D-1))
    if d == 2:
        grad[:, 1] = np.sum(gt * ds[1], axis=1)
    else:
        gt = gt.reshape(t_n, k, k)
        grad[:, 1] = np.einsum("tjk,tj,tk->t", gt, ds[1], cs[2])
        grad[:, 2] = np.einsum("tjk,tj,tk->t", gt, cs[1], ds[2])
    return e, grad * w[:, None] / size


# Long (> 60 lines) by its docstring; the knots are optimised by _optimised_knots.
def optimise_ergodic(
    initial: SearchTrajectory,
    exploration: ExplorationDistribution,
    *,
    speed: float,
    angular_speed: float | None = None,
    control_weight: float = 10.0,
    iterations: int = 200,
    n_knots: int | None = None,
    rate_hz: float = 100.0,
    box: tuple[np.ndarray, np.ndarray] | None = None,
    length: float | None = None,
    keep_length: bool = True,
    method: str = "ergodic-opt",
) -> SearchTrajectory:
    """Lower the ergodic metric of ``initial`` (same start, same weighted length).

    The trajectory is resampled to ``n_knots`` points equally spaced in time (default: a
    quarter of its samples, within 200-2000); the cost is
    ``E + control_weight · E_0 · mean((|Δx| / L̄ - 1)²)``: the control term of J becomes a
    speed constraint (the time is fixed, so no step jumps), scaled to the initial metric
    ``E_0``; the start stays fixed; ``L̄`` is the mean initial knot step. With
    ``keep_length`` (default) ``iterations`` more follow with the speed term 10 times heavier
    and ``L̄`` aiming 2 % beyond ``length`` (m, rz weighted; default the initial path's), and
    the re-timed path is cut at ``length`` (it comes out within 1 %); without, the path comes
    out 3-15 % longer than asked. ``box`` is the cosine basis's domain (default p_e's
    :func:`~teachfit.trajectories.ergodic.search_box` around the start). The result is
    re-timed at ``speed`` like every search trajectory, named ``method``, and carries
    ``meta["ergodic_metric"]`` (after) and ``meta["ergodic_metric_initial"]``; if the
    optimisation did not lower the metric, ``initial`` is returned (0 iterations).
    """
    dims = initial.dims
    if len(dims) not in (2, 3) or tuple(exploration.dims) != tuple(dims):
        raise PlanningError(f"need a 2D or 3D trajectory with p_e's dims, got {dims}")
    if n_knots is None:
        n_knots = int(np.clip(initial.t.size // 4, 200, 2000))
    if n_knots < 8 or iterations < 1 or control_weight < 0:
        raise PlanningError("need n_knots >= 8, iterations >= 1, control_weight >= 0")
    scale = float(initial.meta.get("length_scale", 1.0))
    w = metric_weights(dims, scale)
    target = initial.path_length(scale) if length is None else float(length)
    grid = np.linspace(initial.t[0], initial.t[-1], n_knots)
    x0 = np.stack([np.interp(grid, initial.t, c) for c in initial.states.T], axis=1)
    lo, hi = search_box(exploration, include=x0[0]) if box is None else box
    basis = CosineBasis(lo, hi, _default_coeffs(len(dims)))
    # free first (steps as the start's knots: SMC's chatter is shorter between knots than
    # along it), then, keeping the length, ``iterations`` more with steps aiming 2 % beyond it
    phi = basis.distribution_coefficients(exploration)
    k_reg = control_weight * ergodic_cost_and_gradient(x0, basis, phi)[0]
    path, nit = _optimised_knots(x0, basis, phi, w, None, k_reg, iterations)
    if keep_length:
        step = _AIM * target / (n_knots - 1)
        path, more = _optimised_knots(path, basis, phi, w, step, _HOLD * k_reg, iterations)
        nit += more
    t, states = timed_path(
        path, dims, speed=speed, angular_speed=angular_speed, length_scale=scale, rate_hz=rate_hz
    )
    if keep_length:  # sampling cuts corners too: cut the timed path, not the knots
        states, t = cut_path(states, w, target, t)
    # reported like every other trajectory's: on the timed states
    e_init = ergodic_metric(initial.states, exploration, t=initial.t, box=box)
    e1 = ergodic_metric(states, exploration, t=t, box=box)
    meta = {**initial.meta, "ergodic_metric_initial": e_init, "length_scale": scale}
    if not e1 < e_init:  # the knots could not represent the start's coverage: keep it
        return replace(initial, meta={**meta, "ergodic_metric": e_init, "optimiser_iterations": 0})
    meta.update(ergodic_metric=e1, optimiser_iterations=nit)
    return SearchTrajectory(t, states, dims, method, start=x0[0].copy(), meta=meta)


def _optimised_knots(
    x0: np.ndarray,
    basis: CosineBasis,
    phi: np.ndarray,
    w: np.ndarray,
    step: float | None,
    k_reg: float,
    iterations: int,
) -> tuple[np.ndarray, int]:
    """The knots ``x0`` (first fixed) after L-BFGS on :class:`_Cost` (steps aiming at ``step``,
    default their mean; speed term weighted ``k_reg``), and the iterations run."""
    if step is None:
        step = float(np.mean(np.linalg.norm(np.diff(x0 * w, axis=0), axis=1))) or 1e-3
    cost = _Cost(x0[0].copy(), basis, phi, w, step, k_reg)
    with threadpool_limits(1):  # BLAS threads on small matrices only contend (10x slower)
        res = minimize(
            cost, x0[1:].ravel(), jac=True, method="L-BFGS-B", options=_options(iterations)
        )
    return np.vstack([x0[0], res.x.reshape(-1, x0.shape[1])]), int(res.nit)


def ergodic_search(
    exploration: ExplorationDistribution,
    *,
    speed: float,
    length: float | None = None,
    duration: float | None = None,
    angular_speed: float | None = None,
    start: np.ndarray | None = None,
    box: tuple[np.ndarray, np.ndarray] | None = None,
    iterations: int = 200,
    method: str = "ergodic",
) -> SearchTrajectory:
    """The default ergodic trajectory: spectral multiscale coverage
    (:func:`~teachfit.trajectories.ergodic.ergodic_trajectory`, same arguments), then
    :func:`optimise_ergodic` at the asked weighted length (within 0.1 %).

    Spectral coverage alone covers worse than RCFS's SMC on short paths (2-5 box sides:
    ``benchmarks/ergodic_vs_rcfs.py``); the optimised trajectory covers better at every length
    measured there, in 0.1-1 s (2D).
    """
    smc = ergodic_trajectory(
        exploration,
        speed=speed,
        length=length,
        duration=duration,
        angular_speed=angular_speed,
        start=start,
        box=box,
    )
    total = _requested_length(exploration.dim, speed, length, duration)
    return optimise_ergodic(
        smc,
        exploration,
        speed=speed,
        angular_speed=angular_speed,
        iterations=iterations,
        box=box,
        length=total,
        method=method,
    )


class _Cost:
    """The optimised cost and its gradient over the free knots (``start`` fixed):
    ``E + k_reg · mean((|Δx| / step - 1)²)``, steps measured with the metric weights ``w``."""

    def __init__(
        self,
        start: np.ndarray,
        basis: CosineBasis,
        phi: np.ndarray,
        w: np.ndarray,
        step: float,
        k_reg: float,
    ) -> None:
        self.start, self.basis, self.phi, self.w = start, basis, phi, w
        self.step, self.k_reg = step, k_reg

    def __call__(self, flat: np.ndarray) -> tuple[float, np.ndarray]:
        w, step, k_reg = self.w, self.step, self.k_reg
        x = np.vstack([self.start, flat.reshape(-1, self.start.size)])
        e, g = ergodic_cost_and_gradient(x, self.basis, self.phi)
        dx = np.diff(x * w, axis=0)
        n = np.maximum(np.linalg.norm(dx, axis=1), 1e-12)
        r = n / step - 1.0  # relative deviation from the initial, uniform speed
        reg = k_reg * float(np.mean(r**2))
        gd = (2.0 * k_reg / r.size) * (r / (n * step))[:, None] * dx * w
        greg = np.zeros_like(x)
        greg[1:] += gd
        greg[:-1] -= gd
        return e + reg, (g + greg)[1:].ravel()


def cut_path(
    path: np.ndarray, w: np.ndarray, length: float, t: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The polyline ``path`` (N, D) with times ``t`` (N,) cut where its length (coordinates
    scaled by ``w``) reaches ``length``; unchanged if it is shorter."""
    seg = np.linalg.norm(np.diff(path * w, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    if cum[-1] <= length:
        return path, t
    i = int(np.searchsorted(cum, length))  # cum[i - 1] < length <= cum[i]
    f = (length - cum[i - 1]) / max(seg[i - 1], 1e-300)
    end = path[i - 1] + f * (path[i] - path[i - 1])
    return np.vstack([path[:i], end]), np.append(t[:i], t[i - 1] + f * (t[i] - t[i - 1]))
