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

from dataclasses import replace

import numpy as np
from scipy.optimize import minimize

from teachfit.core.errors import PlanningError
from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.ergodic import CosineBasis, _default_coeffs, ergodic_metric, search_box
from teachfit.trajectories.tshix import SearchTrajectory, metric_weights, timed_path


def _cos_sin(basis: CosineBasis, u: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
    kk = np.arange(basis.n_coeffs)
    arg = [np.pi * u[:, [i]] * kk for i in range(basis.dim)]
    return [np.cos(a) for a in arg], [-np.pi * kk * np.sin(a) for a in arg]


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
    if d == 2:
        c = np.einsum("t,ti,tj->ij", w, cs[0], cs[1], optimize=True) / basis.norm
    else:
        c = np.einsum("t,ti,tj,tk->ijk", w, cs[0], cs[1], cs[2], optimize=True) / basis.norm
    diff = c - phi
    e = float(np.sum(basis.weights * diff**2))
    g = 2.0 * basis.weights * diff / basis.norm  # dE/dc_k, divided by h_k for dc/du
    grad = np.empty_like(s)
    if d == 2:
        grad[:, 0] = np.einsum("ij,ti,tj->t", g, ds[0], cs[1], optimize=True)
        grad[:, 1] = np.einsum("ij,ti,tj->t", g, cs[0], ds[1], optimize=True)
    else:
        grad[:, 0] = np.einsum("ijk,ti,tj,tk->t", g, ds[0], cs[1], cs[2], optimize=True)
        grad[:, 1] = np.einsum("ijk,ti,tj,tk->t", g, cs[0], ds[1], cs[2], optimize=True)
        grad[:, 2] = np.einsum("ijk,ti,tj,tk->t", g, cs[0], cs[1], ds[2], optimize=True)
    return e, grad * w[:, None] / size


# Long (> 60 lines) by its docstring; the cost is _Cost, the body sets it up and
# re-times the result.
def optimise_ergodic(
    initial: SearchTrajectory,
    exploration: ExplorationDistribution,
    *,
    speed: float,
    angular_speed: float | None = None,
    control_weight: float = 1.0,
    iterations: int = 200,
    n_knots: int | None = None,
    rate_hz: float = 100.0,
) -> SearchTrajectory:
    """Lower the ergodic metric of ``initial`` (same start, about the same length).

    The trajectory is resampled to ``n_knots`` points equally spaced in time (default: a
    quarter of its samples, within 200-2000); the cost is
    ``E + control_weight · E_0 · mean((|Δx| / L̄ - 1)²)`` with ``L̄`` the mean initial step:
    the control term of J becomes a speed constraint (the time is fixed, so the length stays
    about the same and no step jumps), scaled to the initial metric ``E_0``; the start stays
    fixed. The result is re-timed at ``speed`` like every search trajectory, and carries
    ``meta["ergodic_metric"]`` (after) and ``meta["ergodic_metric_initial"]``.
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
    grid = np.linspace(initial.t[0], initial.t[-1], n_knots)
    x0 = np.stack([np.interp(grid, initial.t, c) for c in initial.states.T], axis=1)
    lo, hi = search_box(exploration, include=x0[0])
    basis = CosineBasis(lo, hi, _default_coeffs(len(dims)))
    phi = basis.distribution_coefficients(exploration)
    step = float(np.mean(np.linalg.norm(np.diff(x0 * w, axis=0), axis=1))) or 1e-3
    start = x0[0].copy()
    e0 = ergodic_cost_and_gradient(x0, basis, phi)[0]
    # the speed term is scaled to the initial metric
    cost = _Cost(start, basis, phi, w, step, control_weight * e0)
    res = minimize(
        cost, x0[1:].ravel(), jac=True, method="L-BFGS-B", options={"maxiter": int(iterations)}
    )
    path = np.vstack([start, res.x.reshape(-1, len(dims))])
    t, states = timed_path(
        path, dims, speed=speed, angular_speed=angular_speed, length_scale=scale, rate_hz=rate_hz
    )
    # reported like every other trajectory's: on the timed states, p_e's default box
    e_init = ergodic_metric(initial.states, exploration, t=initial.t)
    e1 = ergodic_metric(states, exploration, t=t)
    if not e1 < e_init:  # the knots could not represent the start's coverage: keep it
        return replace(
            initial,
            meta={
                **initial.meta,
                "ergodic_metric_initial": e_init,
                "ergodic_metric": e_init,
                "optimiser_iterations": 0,
            },
        )
    meta = {
        **initial.meta,
        "ergodic_metric_initial": e_init,
        "ergodic_metric": e1,
        "optimiser_iterations": int(res.nit),
        "length_scale": scale,
    }
    return SearchTrajectory(t, states, dims, "ergodic-opt", start=start, meta=meta)


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
