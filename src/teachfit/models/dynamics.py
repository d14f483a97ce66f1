"""Task dynamics: joint Gaussian (mixture) over (Δs, a) and feed-forward by conditioning (GMR).

For one component with ``μ = [μ_s; μ_a]`` and ``Σ = [[Σ_ss, Σ_sa], [Σ_as, Σ_aa]]`` the action
wrench for a desired step Δs* is distributed as ``N(μ*, Σ*)`` with

    μ*  = μ_a + Σ_as Σ_ss^{-1} (Δs* - μ_s)
    Σ*  = Σ_aa - Σ_as Σ_ss^{-1} Σ_sa .

For K components (Gaussian mixture regression) with responsibilities
``h_k(Δs*) = w_k N(Δs* | μ_s,k, Σ_ss,k) / Σ_j w_j N(Δs* | μ_s,j, Σ_ss,j)``:

    μ*  = Σ_k h_k μ*_k,     Σ* = Σ_k h_k (Σ*_k + μ*_k μ*_kᵀ) - μ* μ*ᵀ .

Δs is a step at the model's sample rate (m, rad per sample); a is the wrench the robot applies
(N for forces, N m for the torque about z), both on the search DOFs in the search frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar, Literal

import numpy as np
from scipy.special import softmax

from teachfit.core.errors import ModelError
from teachfit.models.exploration import fit_regularised_gmm
from teachfit.models.mixture import GaussianMixture, component_logpdf

#: Absolute standard-deviation floors: steps (m or rad per sample) and actions (N or N m).
STEP_FLOOR = {"x": 1e-7, "y": 1e-7, "z": 1e-7, "rz": 1e-6}
ACTION_FLOOR = {"x": 1e-3, "y": 1e-3, "z": 1e-3, "rz": 1e-4}


@dataclass(frozen=True)
class DynamicsModel(GaussianMixture):
    """Gaussian mixture over the joint vector ``[Δs, a]`` (length 2D).

    Attributes
    ----------
    dims : tuple of str
        Search DOFs (D).
    weights : ndarray, shape (K,)
    means : ndarray, shape (K, 2D)
        ``[μ_s, μ_a]`` per component.
    covs : ndarray, shape (K, 2D, 2D)
        Joint covariances, symmetric positive definite.
    """

    KIND: ClassVar[str] = "dynamics model"
    #: derived in ``__post_init__``: the gain Σ_as Σ_ss⁻¹ (K, D, D) and the conditional
    #: covariance of the action given the step (K, D, D)
    _gain: np.ndarray = field(init=False, repr=False, compare=False)
    _cond_cov: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        d, cov = self.dim, self.covs
        s, a = slice(0, d), slice(d, 2 * d)
        # Gain Σ_as Σ_ss^{-1} per component: solve Σ_ss Gᵀ = Σ_sa (Σ_ss symmetric).
        gain = np.swapaxes(np.linalg.solve(cov[:, s, s], cov[:, s, a]), 1, 2)  # (K, D, D)
        cond = cov[:, a, a] - gain @ cov[:, s, a]
        object.__setattr__(self, "_gain", gain)
        object.__setattr__(self, "_cond_cov", 0.5 * (cond + np.swapaxes(cond, 1, 2)))

    def _shaped(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = len(self.dims)
        mu = np.asarray(self.means, dtype=float).reshape(w.size, 2 * d)
        return mu, np.asarray(self.covs, dtype=float).reshape(w.size, 2 * d, 2 * d)

    def condition(self, step: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Conditional mean and covariance of the action given steps.

        Parameters
        ----------
        step : ndarray, shape (M, D) or (D,)
            Desired steps Δs* (per sample at the model's rate).

        Returns
        -------
        mean : ndarray, shape (M, D) or (D,)
            μ* (N, N m).
        cov : ndarray, shape (M, D, D) or (D, D)
            Σ*.
        """
        x = np.asarray(step, dtype=float)
        single = x.ndim == 1
        x = np.atleast_2d(x)
        d = self.dim
        if x.shape[1] != d or not np.all(np.isfinite(x)):
            raise ModelError(f"steps must be finite with {d} columns, got shape {x.shape}")
        mu_s, mu_a = self.means[:, :d], self.means[:, d:]
        mk = mu_a[None] + np.einsum("kij,mkj->mki", self._gain, x[:, None, :] - mu_s[None])
        if self.weights.size == 1:
            mean = mk[:, 0]
            cov = np.broadcast_to(self._cond_cov[0], (x.shape[0], d, d)).copy()
        else:
            logp = component_logpdf(x, mu_s, self.covs[:, :d, :d]) + np.log(self.weights)[None]
            h = softmax(logp, axis=1)  # (M, K)
            mean = np.einsum("mk,mki->mi", h, mk)
            second = np.einsum(
                "mk,mkij->mij", h, self._cond_cov[None] + np.einsum("mki,mkj->mkij", mk, mk)
            )
            cov = second - np.einsum("mi,mj->mij", mean, mean)
        return (mean[0], cov[0]) if single else (mean, cov)

    def feedforward(self, step: np.ndarray) -> np.ndarray:
        """Feed-forward action wrench μ*(Δs*), shape like ``step``."""
        return self.condition(step)[0]


def fit_dynamics(
    steps: np.ndarray,
    actions: np.ndarray,
    dims: Sequence[str],
    *,
    n_components: int | Literal["bic"] = 1,
    max_components: int = 4,
    rel_floor: float = 0.05,
    seed: int = 0,
) -> DynamicsModel:
    """Maximum-likelihood (regularised) Gaussian or GMM over ``[Δs, a]``.

    ``steps`` and ``actions`` are (M, D) each. Raises ModelError when the shapes disagree, data
    are not finite, there are fewer than 2D + 1 pairs, or the steps are all identical (the
    teacher never moved). Floors: :data:`STEP_FLOOR`, :data:`ACTION_FLOOR`.
    """
    dims = tuple(dims)
    s = np.asarray(steps, dtype=float)
    a = np.asarray(actions, dtype=float)
    if s.ndim != 2 or s.shape != a.shape or s.shape[1] != len(dims):
        raise ModelError(f"steps {s.shape} and actions {a.shape} must both be (M, {len(dims)})")
    if np.all(np.isfinite(s)) and np.all(np.ptp(s, axis=0) == 0):
        raise ModelError("dynamics: all steps are identical (constant data)")
    floor = np.array(
        [STEP_FLOOR.get(d, 1e-7) for d in dims] + [ACTION_FLOOR.get(d, 1e-3) for d in dims]
    )
    w, mu, cov = fit_regularised_gmm(
        np.hstack([s, a]),
        floor,
        n_components=n_components,
        max_components=max_components,
        rel_floor=rel_floor,
        seed=seed,
    )
    return DynamicsModel(dims, w, mu, cov)
