"""The Gaussian-mixture value type shared by the exploration distribution and the dynamics model.

    p(x) = Σ_k w_k N(x | μ_k, Σ_k),   x ∈ R^n

with weights ``w`` (K,), means ``μ`` (K, n) and covariances ``Σ`` (K, n, n). The subclasses give
``x`` its meaning: a search state (:class:`~teachfit.models.exploration.ExplorationDistribution`,
n = D) or a step and its action wrench (:class:`~teachfit.models.dynamics.DynamicsModel`,
n = 2D).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Self

import numpy as np
from scipy.special import logsumexp

from teachfit.core.errors import ModelError


def component_logpdf(x: np.ndarray, means: np.ndarray, covs: np.ndarray) -> np.ndarray:
    """log N(x | μ_k, Σ_k) for x (M, n), means (K, n), covs (K, n, n); returns (M, K)."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    d = means.shape[1]
    chol = np.linalg.cholesky(covs)  # (K, n, n)
    diff = x[:, None, :] - means[None]  # (M, K, n)
    sol = np.linalg.solve(chol[None], diff[..., None])[..., 0]  # (M, K, n)
    logdet = 2.0 * np.log(np.diagonal(chol, axis1=1, axis2=2)).sum(axis=1)
    return -0.5 * (np.sum(sol**2, axis=2) + logdet[None] + d * np.log(2.0 * np.pi))


def mixture_logpdf(
    x: np.ndarray, weights: np.ndarray, means: np.ndarray, covs: np.ndarray
) -> np.ndarray:
    """log Σ_k w_k N(x | μ_k, Σ_k) for x (M, n); returns (M,)."""
    return logsumexp(component_logpdf(x, means, covs) + np.log(weights)[None], axis=1)


@dataclass(frozen=True)
class GaussianMixture:
    """Validated, immutable mixture parameters over named DOFs.

    Attributes
    ----------
    dims : tuple of str
        The DOFs the mixture is over (D names; the vector may be a multiple of D long).
    weights : ndarray, shape (K,)
        Mixture weights, positive; normalised to sum to 1.
    means : ndarray, shape (K, n)
    covs : ndarray, shape (K, n, n)
        Symmetric positive definite.
    """

    dims: tuple[str, ...]
    weights: np.ndarray
    means: np.ndarray
    covs: np.ndarray

    #: what the mixture is, in error messages
    KIND: ClassVar[str] = "Gaussian mixture"

    def __post_init__(self) -> None:
        w = np.asarray(self.weights, dtype=float)
        mu, cov = self._shaped(w)
        if not (np.all(np.isfinite(w)) and np.all(np.isfinite(mu)) and np.all(np.isfinite(cov))):
            raise ModelError(f"{self.KIND} has NaN or inf parameters")
        if np.any(w <= 0) or abs(w.sum() - 1.0) > 1e-6:
            raise ModelError(f"{self.KIND}: mixture weights must be positive and sum to 1")
        if not np.allclose(cov, np.swapaxes(cov, 1, 2), rtol=1e-9, atol=1e-15):
            raise ModelError(f"{self.KIND}: covariances must be symmetric")
        try:
            np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:
            raise ModelError(f"{self.KIND}: covariances must be positive definite") from None
        object.__setattr__(self, "dims", tuple(self.dims))
        object.__setattr__(self, "weights", w / w.sum())
        object.__setattr__(self, "means", mu)
        object.__setattr__(self, "covs", cov)

    def _shaped(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(means (K, n), covs (K, n, n))`` from the given fields; raise on a mismatch."""
        mu = np.atleast_2d(np.asarray(self.means, dtype=float))
        cov = np.asarray(self.covs, dtype=float).reshape(mu.shape[0], mu.shape[1], mu.shape[1])
        if len(self.dims) != mu.shape[1] or w.shape != (mu.shape[0],):
            raise ModelError(
                f"inconsistent shapes: dims {self.dims}, weights {w.shape}, means {mu.shape}"
            )
        return mu, cov

    @property
    def dim(self) -> int:
        """Number of DOFs D."""
        return len(self.dims)

    @property
    def n_components(self) -> int:
        """Number of mixture components K."""
        return self.weights.size

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready parameters (lists of floats)."""
        return {
            "dims": list(self.dims),
            "weights": self.weights.tolist(),
            "means": self.means.tolist(),
            "covs": self.covs.tolist(),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Self:
        """Inverse of :meth:`to_dict`; raises ModelError on missing keys or bad values."""
        try:
            return cls(
                tuple(d["dims"]), np.array(d["weights"]), np.array(d["means"]), np.array(d["covs"])
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ModelError(f"invalid {cls.KIND}: {exc}") from exc
