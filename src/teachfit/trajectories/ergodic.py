"""Ergodic search by spectral multiscale coverage (Mathew & Mezic), for D = 2 or 3.

Coordinates are normalised to the unit box, ``u_d = (s_d - lo_d) / (hi_d - lo_d)``, with the
orthonormal cosine basis

    f_k(u) = Π_d cos(π k_d u_d) / h_k,     h_k = sqrt(Π_d (1 if k_d = 0 else 1/2)),

k ∈ {0..K-1}^D. The ergodic metric of a trajectory u(t), t ∈ [0, T], is

    E = Σ_k Λ_k (c_k - φ_k)²,   c_k = (1/T) ∫ f_k(u(t)) dt,   Λ_k = (1 + |k|²)^(-(D+1)/2).

φ_k of a Gaussian N(μ, Σ) (in u coordinates) is closed form through its characteristic function:
writing the product of cosines as a sum over sign patterns σ ∈ {±1}^D,

    φ_k = 2^(-D) / h_k Σ_σ exp(-½ ω_σᵀ Σ ω_σ) cos(ω_σᵀ μ),   ω_σ = π (σ ∘ k).

This integral over all of R^D equals the coefficient of the density *folded* into the box by
reflection at its faces (the basis is even and 2-periodic), so no mass is lost at the border; a
mixture's φ_k is the weighted sum of its components'. The SMC feedback law moves at constant
speed v against the gradient of the accumulated coefficient error:

    S_k(t) = ∫_0^t (f_k(u) - φ_k) dτ,   B = Σ_k Λ_k S_k ∇f_k(u),   ṡ = -v B / ‖B‖

(gradients taken in the metric where rz counts ``length_scale`` metres per radian). Written here
because no maintained Python package provides SMC with closed-form Gaussian coefficients.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from teachfit.core.errors import PlanningError
from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.tshix import (
    SearchTrajectory,
    default_length_scale,
    metric_weights,
    timed_path,
)


def search_box(
    exploration: ExplorationDistribution,
    *,
    n_sigma: float = 3.0,
    margin: float = 0.1,
    include: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Box ``(lo, hi)`` = p_e's n_sigma box, grown to contain ``include`` (default the origin),
    then widened by ``margin`` × its size on every side."""
    lo, hi = exploration.bounding_box(n_sigma)
    p = np.zeros(exploration.dim) if include is None else np.asarray(include, float)
    lo, hi = np.minimum(lo, p), np.maximum(hi, p)
    size = hi - lo
    return lo - margin * size, hi + margin * size


@dataclass(frozen=True)
class CosineBasis:
    """Cosine basis on the box ``[lo, hi]`` with K coefficients per dimension.

    Coefficient arrays have shape (K,)*D; ``weights`` holds Λ_k, ``norm`` holds h_k.
    """

    lo: np.ndarray
    hi: np.ndarray
    n_coeffs: int
    #: derived in ``__post_init__``: indices k (D, K, ..., K), h_k and Λ_k (K,)*D
    k: np.ndarray = field(init=False, repr=False, compare=False)
    norm: np.ndarray = field(init=False, repr=False, compare=False)
    weights: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        lo, hi = np.asarray(self.lo, float), np.asarray(self.hi, float)
        if lo.shape != hi.shape or lo.ndim != 1 or lo.size not in (1, 2, 3):
            raise PlanningError("box must be 1-3 dimensional")
        if not np.all(hi > lo) or self.n_coeffs < 2:
            raise PlanningError("box must have positive size and n_coeffs >= 2")
        d = lo.size
        k = np.indices((self.n_coeffs,) * d)  # (D, K, ..., K)
        norm = np.sqrt(np.prod(np.where(k == 0, 1.0, 0.5), axis=0))
        lam = (1.0 + np.sum(k**2, axis=0)) ** (-(d + 1) / 2.0)
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)
        object.__setattr__(self, "k", k)
        object.__setattr__(self, "norm", norm)
        object.__setattr__(self, "weights", lam)

    @property
    def dim(self) -> int:
        return self.lo.size

    def to_unit(self, s: np.ndarray) -> np.ndarray:
        """u = (s - lo) / (hi - lo)."""
        return (np.asarray(s, float) - self.lo) / (self.hi - self.lo)

    def gaussian_coefficients(self, mean: np.ndarray, cov: np.ndarray) -> np.ndarray:
        """φ_k of N(mean, cov) given in state units (closed form; see module docstring)."""
        size = self.hi - self.lo
        mu = (np.asarray(mean, float) - self.lo) / size
        sig = np.asarray(cov, float) / np.outer(size, size)
        d = self.dim
        kf = self.k.reshape(d, -1).T * np.pi  # (M, D)
        acc = np.zeros(kf.shape[0])
        for signs in itertools.product((1.0, -1.0), repeat=d - 1):
            om = kf * np.array((1.0, *signs))  # σ and -σ give the same term: fix σ_0 = +1
            quad = np.einsum("mi,ij,mj->m", om, sig, om)
            acc += 2.0 * np.exp(-0.5 * quad) * np.cos(om @ mu)
        return (acc / 2.0**d).reshape(self.k.shape[1:]) / self.norm

    def distribution_coefficients(self, exploration: ExplorationDistribution) -> np.ndarray:
        """φ_k of a Gaussian mixture: Σ_j w_j φ_k(N(μ_j, Σ_j))."""
        return sum(
            w * self.gaussian_coefficients(m, c)
            for w, m, c in zip(
                exploration.weights, exploration.means, exploration.covs, strict=True
            )
        )

    def trajectory_coefficients(
        self, states: np.ndarray, t: np.ndarray | None = None
    ) -> np.ndarray:
        """c_k = time average of f_k along ``states`` (T, D); trapezoidal weights if ``t`` given."""
        u = self.to_unit(states)
        if t is None:
            w = np.full(u.shape[0], 1.0 / u.shape[0])
        else:
            dt = np.diff(np.asarray(t, float))
            w = np.zeros(u.shape[0])
            w[:-1] += dt / 2
            w[1:] += dt / 2
            w /= w.sum()
        kk = np.arange(self.n_coeffs)
        cs = [np.cos(np.pi * u[:, [i]] * kk) for i in range(self.dim)]  # (T, K) each
        if self.dim == 1:
            c = w @ cs[0]
        elif self.dim == 2:
            c = np.einsum("t,ti,tj->ij", w, cs[0], cs[1], optimize=True)
        else:
            c = np.einsum("t,ti,tj,tk->ijk", w, cs[0], cs[1], cs[2], optimize=True)
        return c / self.norm

    def metric(self, c: np.ndarray, phi: np.ndarray) -> float:
        """E = Σ_k Λ_k (c_k - φ_k)²."""
        return float(np.sum(self.weights * (c - phi) ** 2))


def _default_coeffs(d: int) -> int:
    return {1: 32, 2: 16, 3: 10}[d]


def ergodic_metric(
    states: np.ndarray,
    exploration: ExplorationDistribution,
    *,
    t: np.ndarray | None = None,
    box: tuple[np.ndarray, np.ndarray] | None = None,
    n_coeffs: int | None = None,
) -> float:
    """Ergodic metric of any trajectory ``states`` (T, D) w.r.t. p_e (dimensionless).

    ``box`` defaults to :func:`search_box` of p_e, ``n_coeffs`` to 16 (2D) or 10 (3D), so values
    of TSHIX, ergodic and baseline trajectories are comparable.
    """
    s = np.asarray(states, float)
    if s.ndim != 2 or s.shape[1] != exploration.dim or s.shape[0] < 1:
        raise PlanningError(f"states must be (T, {exploration.dim})")
    lo, hi = search_box(exploration) if box is None else box
    basis = CosineBasis(lo, hi, n_coeffs or _default_coeffs(exploration.dim))
    return basis.metric(
        basis.trajectory_coefficients(s, t), basis.distribution_coefficients(exploration)
    )


# Long (> 60 lines) by its numpydoc docstring; the integration is _smc_path.
def ergodic_trajectory(
    exploration: ExplorationDistribution,
    *,
    speed: float,
    length: float | None = None,
    duration: float | None = None,
    angular_speed: float | None = None,
    length_scale: float | None = None,
    start: np.ndarray | None = None,
    n_coeffs: int | None = None,
    box: tuple[np.ndarray, np.ndarray] | None = None,
    steps_per_box: int = 200,
    rate_hz: float = 100.0,
) -> SearchTrajectory:
    """Spectral-multiscale-coverage trajectory for p_e (D = 2 or 3).

    Parameters
    ----------
    exploration : ExplorationDistribution
        p_e in the search frame.
    speed : float
        Speed along the weighted path, m/s (rz counted at ``length_scale`` m/rad).
    length, duration : float
        Requested weighted path length (m) or duration (s); exactly one.
    angular_speed : float, optional
        If given, the output is timed with the rz speed limit too (see :func:`timed_path`).
    length_scale : float, optional
        m / rad for rz (default :func:`default_length_scale`).
    start : ndarray (D,), optional
        First state (default: the origin).
    n_coeffs : int, optional
        K per dimension (default 16 in 2D, 10 in 3D).
    box : (lo, hi), optional
        Domain; default :func:`search_box`.
    steps_per_box : int
        Integration step = smallest weighted box side / steps_per_box.
    rate_hz : float
        Output sample rate.

    Returns
    -------
    SearchTrajectory
        ``method="ergodic"``; ``meta["ergodic_metric"]`` holds E of the result.
    """
    d = exploration.dim
    total = _requested_length(d, speed, length, duration)
    ls = default_length_scale(exploration) if length_scale is None else float(length_scale)
    w = metric_weights(exploration.dims, ls)
    s0 = np.zeros(d) if start is None else np.asarray(start, float)
    lo, hi = search_box(exploration, include=s0) if box is None else box
    basis = CosineBasis(lo, hi, n_coeffs or _default_coeffs(d))
    phi = basis.distribution_coefficients(exploration)
    path = _smc_path(basis, phi, basis.to_unit(s0), w, total, speed, steps_per_box)
    states = basis.lo + path * (basis.hi - basis.lo)
    t, timed = timed_path(
        states,
        exploration.dims,
        speed=speed,
        angular_speed=angular_speed,
        length_scale=ls,
        rate_hz=rate_hz,
    )
    metric = basis.metric(basis.trajectory_coefficients(timed, t), phi)
    return SearchTrajectory(
        t,
        timed,
        exploration.dims,
        "ergodic",
        start=s0,
        meta={
            "ergodic_metric": metric,
            "box_lo": basis.lo.tolist(),
            "box_hi": basis.hi.tolist(),
            "n_coeffs": basis.n_coeffs,
            "length_scale": ls,
        },
    )


def _requested_length(d: int, speed: float, length: float | None, duration: float | None) -> float:
    """The weighted path length (m) asked for by ``length`` or ``duration`` at ``speed``."""
    if d not in (2, 3):
        raise PlanningError(f"ergodic search supports D = 2 or 3, got {d}")
    if (length is None) == (duration is None):
        raise PlanningError("give exactly one of length or duration")
    if not (np.isfinite(speed) and speed > 0):
        raise PlanningError(f"speed must be positive, got {speed}")
    total = float(length) if length is not None else float(duration or 0.0) * speed
    if not (np.isfinite(total) and total > 0):
        raise PlanningError("length / duration must be positive")
    return float(total)


def _smc_path(
    basis: CosineBasis,
    phi: np.ndarray,
    u: np.ndarray,
    w: np.ndarray,
    total: float,
    speed: float,
    steps_per_box: int,
) -> np.ndarray:
    """(n + 1, D) states in the unit box from ``u``: each step of the spectral multiscale
    coverage law goes ``total / n`` in the metric (weights ``w``) down the gradient of the
    ergodic metric's running sum, reflected at the box's faces."""
    d = u.shape[0]
    lam_h = basis.weights / basis.norm
    size_w = (basis.hi - basis.lo) * w  # box sides in the metric
    ds = float(size_w.min()) / steps_per_box
    n_steps = int(np.ceil(total / ds))
    if n_steps > 2_000_000:
        raise PlanningError("requested trajectory too long for the integration step")
    ds = total / n_steps
    dt = ds / speed
    pik = np.pi * np.arange(basis.n_coeffs)
    path = np.empty((n_steps + 1, d))
    path[0] = u
    acc = np.zeros_like(phi)  # Σ_steps (f_k / h_k ... ) accumulated as S_k * h_k
    phi_h = phi * basis.norm
    scale_u = ds / size_w  # a metric step of length ds in u units, per dimension
    rng_dir = np.random.default_rng(0)  # only for the rare B = 0 tie
    for i in range(n_steps):
        c = np.cos(pik * u[:, None])  # (D, K)
        s = -pik * np.sin(pik * u[:, None])  # d/du cos(π k u)
        if d == 2:
            acc += (np.outer(c[0], c[1]) - phi_h) * dt
            g = lam_h * acc / basis.norm
            b = np.array([s[0] @ g @ c[1], c[0] @ g @ s[1]])
        else:
            acc += (c[0][:, None, None] * c[1][None, :, None] * c[2][None, None, :] - phi_h) * dt
            g = lam_h * acc / basis.norm
            gz = g @ c[2]
            b = np.array([s[0] @ gz @ c[1], c[0] @ gz @ s[1], c[0] @ (g @ s[2]) @ c[1]])
        grad = b / size_w  # gradient w.r.t. the weighted state
        nrm = np.linalg.norm(grad)
        direction = -grad / nrm if nrm > 0 else rng_dir.standard_normal(d)
        if nrm == 0:
            direction /= np.linalg.norm(direction)
        u = u + direction * scale_u
        u = np.abs(u)  # reflect at the faces of the unit box
        u = np.where(u > 1.0, 2.0 - u, u)
        path[i + 1] = u
    return path
