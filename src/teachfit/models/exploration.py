"""Exploration distribution p_e(s) over the demonstrated search states.

    p_e(s) = Σ_k w_k N(s | μ_k, Σ_k),   s ∈ R^D (search frame; m for x, y, rad for rz)

with K = 1 (maximum-likelihood Gaussian, the paper's model) or K chosen by BIC up to a cap
(scikit-learn ``GaussianMixture``). Demonstrations often lie in a lower-dimensional subspace
(a straight sweep; no rotation at all), so the covariances are regularised:

    Σ_k <- Σ_k + diag((ρ σ_d)² + ε_d²)

with σ_d the data's standard deviation per dimension, ρ a relative floor (default 0.05) and ε_d
an absolute floor (0.1 mm for lengths, 1 mrad for angles). The floors are small compared with the
data's spread, so the model stays well-posed yet only puts mass where the teacher searched.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
from scipy.stats.qmc import MultivariateNormalQMC
from sklearn import mixture as sk_mixture

from teachfit.core.errors import ModelError
from teachfit.models.mixture import GaussianMixture, mixture_logpdf

#: Default absolute standard-deviation floor per kind of DOF (m for lengths, rad for angles).
ABS_FLOOR = {"x": 1e-4, "y": 1e-4, "z": 1e-4, "rz": 1e-3}


def _check_data(x: np.ndarray, what: str) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.ndim != 2:
        raise ModelError(f"{what}: expected a 2-D array (N, D), got shape {x.shape}")
    n, d = x.shape
    if not np.all(np.isfinite(x)):
        raise ModelError(f"{what}: data contains NaN or inf")
    if n < d + 1:
        raise ModelError(f"{what}: need at least D + 1 = {d + 1} samples, got {n}")
    if np.all(np.ptp(x, axis=0) == 0):
        raise ModelError(f"{what}: all samples are identical (constant data)")
    return x


# Long (> 60 lines) by its numpydoc docstring; the body (the BIC loop over component counts)
# is one step.
def fit_regularised_gmm(
    x: np.ndarray,
    abs_floor: np.ndarray,
    *,
    n_components: int | Literal["bic"] = 1,
    max_components: int = 4,
    rel_floor: float = 0.05,
    seed: int = 0,
    covariance: Literal["full", "diag"] = "full",
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fit a regularised Gaussian mixture; returns ``(weights (K,), means (K,D), covs (K,D,D))``.

    The fit runs on standardised data ``z_d = (x_d - mean_d) / scale_d`` with
    ``scale_d = max(σ_d, ε_d)`` and scikit-learn's ``reg_covar = ρ²``; the covariances are mapped
    back and ``diag(ε_d²)`` is added. With ``n_components="bic"`` K = 1..``max_components``
    (at most N // (D + 1)) are fitted and the lowest BIC wins. K = 1 is the closed-form
    maximum-likelihood estimate (mean, biased covariance). ``covariance="diag"`` keeps only
    the per-DOF variances: with very few demonstrations the cross-correlations mostly record
    where they happened to start, e.g. x against rz for two demos from opposite corners.
    """
    if covariance not in ("full", "diag"):
        raise ModelError(f"covariance must be 'full' or 'diag', got {covariance!r}")
    x = _check_data(x, "fit")
    n, d = x.shape
    abs_floor = np.broadcast_to(np.asarray(abs_floor, dtype=float), (d,))
    if rel_floor < 0 or np.any(abs_floor < 0):
        raise ModelError("covariance floors must be non-negative")
    centre = x.mean(axis=0)
    scale = np.maximum(x.std(axis=0), np.maximum(abs_floor, 1e-300))
    z = (x - centre) / scale
    candidates: Sequence[int]
    if n_components == "bic":
        candidates = range(1, max(1, min(int(max_components), n // (d + 1))) + 1)
    else:
        if int(n_components) < 1 or int(n_components) > n:
            raise ModelError(f"n_components must be in 1..{n}, got {n_components}")
        candidates = [int(n_components)]
    best: tuple[float, np.ndarray, np.ndarray, np.ndarray] | None = None
    for k in candidates:
        if k == 1:
            w = np.ones(1)
            mu = z.mean(axis=0, keepdims=True)
            cov = np.cov(z.T, bias=True).reshape(d, d)
            if covariance == "diag":
                cov = np.diag(np.diag(cov))
            cov = (cov + rel_floor**2 * np.eye(d))[None]
            if len(candidates) == 1:
                best = (0.0, w, mu, cov)
                break
            logl = mixture_logpdf(z, w, mu, cov).sum()
            n_cov = d if covariance == "diag" else d * (d + 1) / 2
            bic = -2.0 * logl + (d + n_cov) * np.log(n)
        else:
            gm = sk_mixture.GaussianMixture(
                n_components=k,
                covariance_type=covariance,
                reg_covar=rel_floor**2,
                random_state=seed,
                n_init=1,
            ).fit(z)
            w, mu, cov, bic = gm.weights_, gm.means_, gm.covariances_, gm.bic(z)
            if covariance == "diag":
                cov = np.stack([np.diag(c) for c in cov])
        if best is None or bic < best[0]:
            best = (bic, w, mu, cov)
    assert best is not None
    _, w, mu, cov = best
    means = centre + mu * scale
    covs = cov * np.outer(scale, scale)[None] + np.diag(abs_floor**2)[None]
    return np.asarray(w, dtype=float), means, covs


@dataclass(frozen=True)
class ExplorationDistribution(GaussianMixture):
    """Gaussian mixture p_e(s) over search states (search frame).

    Attributes
    ----------
    dims : tuple of str
        Search DOFs (length D), e.g. ``("x", "y", "rz")``.
    weights : ndarray, shape (K,)
        Mixture weights, positive, summing to 1.
    means : ndarray, shape (K, D)
        Component means (m, rad).
    covs : ndarray, shape (K, D, D)
        Component covariances, symmetric positive definite (m², m·rad, rad²).
    """

    KIND: ClassVar[str] = "exploration distribution"

    @property
    def mean(self) -> np.ndarray:
        """Mixture mean Σ_k w_k μ_k, shape (D,)."""
        return self.weights @ self.means

    @property
    def cov(self) -> np.ndarray:
        """Mixture covariance Σ_k w_k (Σ_k + μ_k μ_kᵀ) - μ μᵀ, shape (D, D)."""
        m = self.mean
        second = np.einsum(
            "k,kij->ij", self.weights, self.covs + np.einsum("ki,kj->kij", self.means, self.means)
        )
        return second - np.outer(m, m)

    def logpdf(self, s: np.ndarray) -> np.ndarray:
        """log p_e(s) for s of shape (M, D) or (D,); returns (M,) or a scalar."""
        s = np.asarray(s, dtype=float)
        out = mixture_logpdf(np.atleast_2d(s), self.weights, self.means, self.covs)
        return out[0] if s.ndim == 1 else out

    def pdf(self, s: np.ndarray) -> np.ndarray:
        """p_e(s) (density in 1 / (m^n rad^r)) for s of shape (M, D) or (D,)."""
        return np.exp(self.logpdf(s))

    def sample(self, n: int, rng: np.random.Generator, *, qmc: bool = False) -> np.ndarray:
        """Draw ``n`` samples (n, D); component counts are multinomial in the weights.

        ``qmc=True`` draws each component's samples as scrambled Sobol points mapped through
        the Gaussian's inverse CDF (:class:`scipy.stats.qmc.MultivariateNormalQMC`): still
        distributed as p_e, but without the clumps and gaps of i.i.d. draws, so a tour through
        them covers the distribution more evenly.
        """
        if not isinstance(n, int | np.integer) or n <= 0:
            raise ModelError(f"number of samples must be a positive integer, got {n!r}")
        counts = rng.multinomial(int(n), self.weights)
        chol = np.linalg.cholesky(self.covs)
        parts = []
        for k, c in enumerate(counts):
            if c == 0:
                continue
            if qmc:
                engine = MultivariateNormalQMC(self.means[k], cov_root=chol[k].T, rng=rng)
                with warnings.catch_warnings():  # Sobol prefers powers of 2; a prefix is fine
                    warnings.simplefilter("ignore", UserWarning)
                    parts.append(engine.random(int(c)))
            else:
                parts.append(self.means[k] + rng.standard_normal((c, self.dim)) @ chol[k].T)
        out = np.concatenate(parts)
        return out[rng.permutation(int(n))]

    def bounding_box(self, n_sigma: float = 3.0) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned box ``(lo (D,), hi (D,))`` covering every component's μ ± n_sigma σ."""
        sd = np.sqrt(np.diagonal(self.covs, axis1=1, axis2=2))
        return (self.means - n_sigma * sd).min(axis=0), (self.means + n_sigma * sd).max(axis=0)

    def mirrored(self, dims: Sequence[str]) -> ExplorationDistribution:
        """The even mixture of p_e and its mirror image with the DOFs ``dims`` negated:

            p_m(s) = (p_e(s) + p_e(F s)) / 2,   F = diag(-1 on dims, +1 elsewhere)

        (2K components). A search relative to its start does not know which way the start
        is off; demonstrations started on one side teach the way back from that side only
        (rz on socket3d: ``docs/notes/variant-samples.md``). ``dims`` empty: unchanged."""
        unknown = sorted(set(dims) - set(self.dims))
        if unknown:
            raise ModelError(f"cannot mirror {unknown}: the model's DOFs are {list(self.dims)}")
        if not dims:
            return self
        f = np.array([-1.0 if d in dims else 1.0 for d in self.dims])
        return ExplorationDistribution(
            self.dims,
            np.concatenate([self.weights, self.weights]) / 2.0,
            np.concatenate([self.means, self.means * f]),
            np.concatenate([self.covs, self.covs * np.outer(f, f)[None]]),
        )

    def scaled(self, factors: np.ndarray) -> ExplorationDistribution:
        """The distribution of ``diag(factors) s`` (e.g. rz in metres via a length scale)."""
        f = np.asarray(factors, dtype=float)
        return ExplorationDistribution(
            self.dims, self.weights, self.means * f, self.covs * np.outer(f, f)[None]
        )


def fit_exploration(
    states: np.ndarray,
    dims: Sequence[str],
    *,
    n_components: int | Literal["bic"] = 1,
    max_components: int = 4,
    rel_floor: float = 0.05,
    abs_floor: Sequence[float] | None = None,
    seed: int = 0,
    covariance: Literal["full", "diag"] = "full",
) -> ExplorationDistribution:
    """Fit p_e(s) to search states.

    Parameters
    ----------
    states : ndarray, shape (N, D)
        Search states (search frame), N >= D + 1, not all identical, finite.
    dims : sequence of str
        DOF names, length D.
    n_components : int or "bic"
        1 (default) = maximum-likelihood Gaussian; an int = that many components; "bic" = the
        count in 1..max_components with the lowest Bayesian information criterion.
    rel_floor, abs_floor
        Regularisation (see module docstring); ``abs_floor`` defaults to :data:`ABS_FLOOR`.
    seed : int
        Seed of the EM initialisation (K > 1).
    covariance : {"full", "diag"}
        Full maximum-likelihood covariances (Ehlers et al. 2019), or per-DOF variances only.
    """
    dims = tuple(dims)
    x = _check_data(states, "exploration")
    if x.shape[1] != len(dims):
        raise ModelError(f"states have {x.shape[1]} columns but dims are {dims}")
    floor = np.array([ABS_FLOOR.get(d, 1e-4) for d in dims]) if abs_floor is None else abs_floor
    w, mu, cov = fit_regularised_gmm(
        x,
        np.asarray(floor, dtype=float),
        n_components=n_components,
        max_components=max_components,
        rel_floor=rel_floor,
        seed=seed,
        covariance=covariance,
    )
    return ExplorationDistribution(dims, w, mu, cov)
