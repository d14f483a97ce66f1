"""Spectral multiscale coverage as RCFS writes it: a benchmark comparator, not a planner.

Re-implemented from the published equations (Mathew & Mezić 2011, *Metrics for ergodicity and
design of ergodic dynamics for multi-agent systems*; Calinon's *Robotics Codes From Scratch*,
``ergodic_control_SMC``), with RCFS's parameters: the domain ``[0, 1]^D`` seen as half of a
period ``L = 2`` (``ω = 2π / L``), ``K = 10`` functions per dimension, and

    f_k(x) = Π_d cos(ω k_d x_d),     Λ_k = (1 + |k|²)^(-(D+1)/2),
    w_k(t) = (1/t) Σ_{τ ≤ t} f_k(x_τ) / L^D,
    ŵ_k    = Fourier coefficients of the Gaussian mixture (closed form, reflected Gaussians),
    u      = -Σ_k Λ_k (w_k(t) - ŵ_k) ∇f_k(x),   u ← u_max u / (‖u‖ + ε),   x ← x + u Δt,

Euler steps of ``u_max Δt = 0.1`` (RCFS: ``u_max = 10``, ``Δt = 0.01``), ``ε = 0.1``, no
reflection at the domain's faces (as RCFS). The comparator runs on the unit box; callers map
their box onto it.
"""

from __future__ import annotations

import itertools

import numpy as np

#: RCFS's settings of ``ergodic_control_SMC`` (2-D)
N_FCT, U_MAX, DT, U_NORM_REG = 10, 10.0, 1e-2, 1e-1


def mixture_coefficients(
    weights: np.ndarray, means: np.ndarray, covs: np.ndarray, n_fct: int = N_FCT
) -> np.ndarray:
    """ŵ_k (flattened, k_0 slowest) of a Gaussian mixture on the unit box (period L = 2):
    each component mirrored over the sign patterns, ``cos(ω kᵀ μ_σ) exp(-½ ω² kᵀ Σ_σ k)``,
    averaged over the patterns and divided by L^D."""
    d = means.shape[1]
    k = np.stack(np.meshgrid(*[np.arange(n_fct)] * d, indexing="ij")).reshape(d, -1)
    om = np.pi  # 2π / L, L = 2
    kk = k.T * om
    out = np.zeros(k.shape[1])
    patterns = [np.array((1.0, *s)) for s in itertools.product((1.0, -1.0), repeat=d - 1)]
    for w, m, c in zip(weights, means, covs, strict=True):
        for sgn in patterns:
            mu, cov = sgn * m, c * np.outer(sgn, sgn)
            quad = np.einsum("mi,ij,mj->m", kk, cov, kk)
            out += w * np.cos(kk @ mu) * np.exp(-0.5 * quad)
    return out / 2.0**d / len(patterns)


def smc_path(
    w_hat: np.ndarray,
    x0: np.ndarray,
    length: float,
    *,
    n_fct: int = N_FCT,
    u_max: float = U_MAX,
    dt: float = DT,
    u_norm_reg: float = U_NORM_REG,
) -> tuple[np.ndarray, np.ndarray]:
    """RCFS's SMC loop from ``x0`` (D,) in the unit box, run until its path is ``length`` long
    (RCFS runs a fixed step count; ε makes its steps shorter than ``u_max Δt`` where the
    gradient is weak): the states (n + 1, D) and the ergodic error ``Σ_k Λ_k (w_k(t) - ŵ_k)²``
    after each step (n,), as RCFS logs it."""
    d = x0.size
    k = np.stack(np.meshgrid(*[np.arange(n_fct)] * d, indexing="ij")).reshape(d, -1)
    lam = (1.0 + np.sum(k**2, axis=0)) ** (-(d + 1) / 2.0)
    om, big_l = np.pi, 2.0
    x = np.asarray(x0, float).copy()
    wt = np.zeros(k.shape[1])
    states, err, walked = [x.copy()], [], 0.0
    for i in range(int(1000 * length / (u_max * dt)) + 1):  # cap: steps 1000x shorter
        if walked >= length:
            break
        ang = om * k * x[:, None]  # (D, M)
        c, s = np.cos(ang), -om * k * np.sin(ang)
        f = np.prod(c, axis=0)
        grad = np.empty((d, k.shape[1]))
        for j in range(d):
            grad[j] = s[j] * np.prod(np.delete(c, j, axis=0), axis=0)
        wt += f / big_l**d
        diff = wt / (i + 1) - w_hat
        u = -grad @ (lam * diff)
        u = u * u_max / (np.linalg.norm(u) + u_norm_reg)
        x = x + u * dt
        walked += float(np.linalg.norm(u * dt))
        states.append(x.copy())
        err.append(float(np.sum(lam * diff**2)))
    return np.array(states), np.array(err)
