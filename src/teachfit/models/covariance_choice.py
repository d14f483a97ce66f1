"""Choosing p_e's covariance structure from the demonstrations themselves.

Ehlers et al. 2019 fits one Gaussian with a full covariance. With two demonstrations started at
opposite corners with opposite yaw, that covariance holds a correlation (x against rz, 0.76 on
``socket3d``) that no third start follows, and TSHIX then misses starts of the other sign
(Table III: 67 % with the full covariance, 100 % with per-DOF variances). Which structure
generalises is measured on the data: **leave one demonstration out**. For each demonstration
``i``, p_e is fitted to the others with each structure and scored by the mean log-density of
demonstration ``i``'s states,

    score(c) = (1 / M) Σ_i  mean_{s ∈ demo i} log p_e^{c, -i}(s),

and the structure with the higher score is chosen (``full`` on a tie: Ehlers et al.'s choice). With
a single demonstration there is nothing held out: Ehlers et al.'s full covariance is kept, and the
choice says so.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from teachfit.core.errors import ModelError

STRUCTURES = ("full", "diag")


@dataclass(frozen=True)
class CovarianceChoice:
    """Which covariance structure p_e uses and why.

    Attributes
    ----------
    covariance : {"full", "diag"}
    criterion : str
        ``"held-out"`` (leave one demonstration out), ``"single demonstration"`` or
        ``"given"`` (asked for by the caller).
    scores : dict
        Mean held-out log-density per state for each structure (nats; empty unless held-out).
    """

    covariance: str
    criterion: str
    scores: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.covariance not in STRUCTURES:
            raise ModelError(f"covariance must be one of {STRUCTURES}, got {self.covariance!r}")

    def describe(self) -> str:
        """One line for a user, e.g. ``diag (held-out log-likelihood: full -9.1, diag -2.3)``."""
        if self.criterion == "held-out":
            parts = ", ".join(f"{k} {v:.2f}" for k, v in self.scores.items())
            return (
                f"{self.covariance} (chosen by leave-one-demonstration-out log-likelihood "
                f"per state: {parts})"
            )
        if self.criterion == "single demonstration":
            return f"{self.covariance} (one demonstration: nothing to hold out; as Ehlers et al.)"
        return f"{self.covariance} (as asked)"

    def to_dict(self) -> dict[str, Any]:
        return {"covariance": self.covariance, "criterion": self.criterion, "scores": self.scores}

    @classmethod
    def from_dict(cls, doc: Any) -> CovarianceChoice:
        try:
            scores = {str(k): float(v) for k, v in dict(doc.get("scores", {})).items()}
            return cls(str(doc["covariance"]), str(doc["criterion"]), scores)
        except (AttributeError, KeyError, TypeError, ValueError) as exc:
            raise ModelError(f"malformed covariance_choice: {exc}") from exc


def choose_covariance(
    per_demo: Sequence[np.ndarray],
    fit: Callable[[np.ndarray, str], Any],
) -> CovarianceChoice:
    """Choose ``full`` or ``diag`` by leave-one-demonstration-out log-likelihood.

    Parameters
    ----------
    per_demo : sequence of ndarray, each shape (N_i, D)
        Search states of each demonstration (search frame; m, rad).
    fit : callable
        ``fit(states, covariance) -> ExplorationDistribution`` (anything with ``logpdf``).
    """
    if len(per_demo) < 2:
        return CovarianceChoice("full", "single demonstration")
    scores: dict[str, float] = {}
    for structure in STRUCTURES:
        per = []
        for i, held in enumerate(per_demo):
            rest = np.vstack([s for j, s in enumerate(per_demo) if j != i])
            per.append(float(np.mean(fit(rest, structure).logpdf(held))))
        scores[structure] = float(np.mean(per))
    best = "diag" if scores["diag"] > scores["full"] else "full"
    return CovarianceChoice(best, "held-out", scores)
