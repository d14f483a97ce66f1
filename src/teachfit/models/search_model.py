"""SearchModel: what is learned from blind search demonstrations, and its file format.

File format (JSON, UTF-8, no pickle)::

    {
      "format": "teachfit.search_model",
      "version": 1,
      "task": "peg2d",                  # task the demonstrations were recorded on
      "dims": ["x", "y"],               # search DOFs, in this order everywhere below
      "rate_hz": 100.0,                 # sample rate of the dynamics' steps Δs
      "speed": 0.01,                    # median teacher speed in the search plane, m/s
      "angular_speed": null,            # median |d rz/dt|, rad/s (null without rz)
      "n_demos": 1,
      "exploration": {"dims": [...], "weights": [K], "means": [K][D], "covs": [K][D][D]},
      "dynamics": {"dims": [...], "weights": [K], "means": [K][2D], "covs": [K][2D][2D]}
                  or null,          # (no wrench recorded: no feed-forward)
      "covariance_choice": {"covariance": "diag", "criterion": "held-out",
                            "scores": {"full": -9.1, "diag": -2.3}}   # optional
    }

Units: m and rad for states and steps (steps per sample at ``rate_hz``), N and N m for actions.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from teachfit.core.atomic import atomic_write_text
from teachfit.core.errors import ModelError
from teachfit.models.covariance_choice import CovarianceChoice, choose_covariance
from teachfit.models.dynamics import DynamicsModel, fit_dynamics
from teachfit.models.exploration import ExplorationDistribution, fit_exploration
from teachfit.models.search_data import SearchData, dims_for_task, search_data, validate_dims

FORMAT = "teachfit.search_model"
VERSION = 1


def _covariance_choice(
    covariance: str,
    demos: list[Any],
    dims: tuple[str, ...],
    rate_hz: float,
    fit: Callable[[np.ndarray, str], ExplorationDistribution],
) -> CovarianceChoice:
    """p_e's covariance structure: ``covariance`` as given (``"full"``, ``"diag"``), or for
    ``"auto"`` chosen by held-out likelihood of each demonstration's states at ``rate_hz``
    (Hz) under ``fit`` (states, structure) on the others. ModelError for another value."""
    if covariance == "auto":
        per_demo = [search_data(d, dims, rate_hz=rate_hz).states for d in demos]
        return choose_covariance(per_demo, fit)
    if covariance in ("full", "diag"):
        return CovarianceChoice(covariance, "given")
    raise ModelError(f"covariance must be 'auto', 'full' or 'diag', got {covariance!r}")


def _fit_dynamics(
    data: SearchData,
    dims: tuple[str, ...],
    n_components: int | Literal["bic"],
    max_components: int,
    rel_floor: float,
    seed: int,
) -> DynamicsModel | None:
    """The dynamics of ``data``'s steps and actions (:func:`fit_dynamics`); None when no
    wrench was recorded (no actions)."""
    if data.actions is None:
        return None
    return fit_dynamics(
        data.steps,
        data.actions,
        dims,
        n_components=n_components,
        max_components=max_components,
        rel_floor=rel_floor,
        seed=seed,
    )


def auto_mirror(dims: Sequence[str]) -> tuple[str, ...]:
    """The DOFs whose sign a search treats as unknown by default: the yaw ``rz`` when it is
    searched. Every task draws its start yaw evenly on both sides of the hole's, while a
    demonstration teaches the turn back from the side it started on only; made even in rz,
    the socket3d variants that missed reach >= 19/20 (``docs/notes/variant-samples.md``).
    Offsets in x and y are not mirrored: the papers' starts lie on one side of the hole."""
    return ("rz",) if "rz" in dims else ()


@dataclass(frozen=True)
class SearchModel:
    """Exploration distribution + dynamics learned for one task.

    Attributes
    ----------
    task : str
    dims : tuple of str
        Search DOFs (D).
    exploration : ExplorationDistribution
        p_e(s) in the search frame.
    dynamics : DynamicsModel or None
        Joint model over (Δs, a); None when the demonstrations had no wrench.
    rate_hz : float
        Sample rate at which Δs was taken.
    speed : float
        Median teacher speed in the search plane, m/s (> 0).
    angular_speed : float or None
        Median teacher |d rz / dt|, rad/s; None when rz is not searched.
    n_demos : int
    covariance_choice : CovarianceChoice or None
        How p_e's covariance structure was chosen (None: not recorded, e.g. an older file).
    """

    task: str
    dims: tuple[str, ...]
    exploration: ExplorationDistribution
    dynamics: DynamicsModel | None
    rate_hz: float
    speed: float
    angular_speed: float | None = None
    n_demos: int = 1
    covariance_choice: CovarianceChoice | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "dims", validate_dims(self.dims))
        if self.exploration.dims != self.dims:
            raise ModelError(f"exploration dims {self.exploration.dims} != model dims {self.dims}")
        if self.dynamics is not None and self.dynamics.dims != self.dims:
            raise ModelError(f"dynamics dims {self.dynamics.dims} != model dims {self.dims}")
        if not (np.isfinite(self.rate_hz) and self.rate_hz > 0):
            raise ModelError(f"rate_hz must be positive, got {self.rate_hz}")
        if not (np.isfinite(self.speed) and self.speed > 0):
            raise ModelError(f"teacher speed must be positive, got {self.speed}")
        if self.n_demos < 1:
            raise ModelError("n_demos must be >= 1")

    @classmethod
    def fit(
        cls,
        demos: Iterable[Any],
        task: str,
        dims: Sequence[str] | None = None,
        *,
        n_components: int | Literal["bic"] = 1,
        max_components: int = 4,
        dynamics_components: int | Literal["bic"] = 1,
        rate_hz: float | None = None,
        rel_floor: float = 0.05,
        seed: int = 0,
        covariance: Literal["auto", "full", "diag"] = "auto",
        mirror: Sequence[str] | Literal["auto"] = "auto",
    ) -> SearchModel:
        """Learn p_e and the dynamics from demonstrations (see :func:`search_data`).

        ``dims`` defaults to the task's search DOFs; ``covariance`` is p_e's covariance type
        (:func:`fit_exploration`), ``"auto"`` choosing it by leave-one-demonstration-out
        likelihood (:mod:`teachfit.models.covariance_choice`; recorded in
        ``covariance_choice``); ``mirror``: DOFs whose sign p_e is made even in
        (:meth:`~teachfit.models.exploration.ExplorationDistribution.mirrored`), ``"auto"``
        those of :func:`auto_mirror`. Raises ModelError for too few or degenerate samples, or a
        teacher who never moved.
        """
        dims = dims_for_task(task) if dims is None else validate_dims(dims)
        demos = [demos] if hasattr(demos, "pos") else list(demos)
        data = search_data(demos, dims, rate_hz=rate_hz)

        def fit(states: np.ndarray, structure: str) -> ExplorationDistribution:
            return fit_exploration(
                states,
                dims,
                n_components=n_components,
                max_components=max_components,
                rel_floor=rel_floor,
                seed=seed,
                covariance=structure,  # type: ignore[arg-type]
            )

        choice = _covariance_choice(covariance, demos, dims, data.rate_hz, fit)
        even = auto_mirror(dims) if mirror == "auto" else tuple(mirror)
        expl = fit(data.states, choice.covariance).mirrored(even)
        dyn = _fit_dynamics(data, dims, dynamics_components, max_components, rel_floor, seed)
        if data.speed <= 0:
            raise ModelError("the demonstrations never move in the search plane")
        return cls(
            task,
            dims,
            expl,
            dyn,
            data.rate_hz,
            data.speed,
            data.angular_speed,
            data.n_demos,
            choice,
        )

    def feedforward(self, velocity: np.ndarray) -> np.ndarray:
        """Feed-forward wrench for desired search velocities (M, D) (m/s, rad/s).

        The velocity is converted to a step at the model's rate, ``Δs* = v / rate_hz``, and
        conditioned on (GMR). Zeros when there is no dynamics model. Returns (M, D), N and N m.
        """
        v = np.atleast_2d(np.asarray(velocity, dtype=float))
        if self.dynamics is None:
            return np.zeros_like(v)
        return self.dynamics.feedforward(v / self.rate_hz)

    def feedforward_along(self, t: np.ndarray, states: np.ndarray) -> np.ndarray:
        """Feed-forward wrench (T, D) along a timed trajectory ``states`` (T, D) at ``t`` (T,)."""
        return self.feedforward(
            np.gradient(np.asarray(states, float), np.asarray(t, float), axis=0)
        )

    def to_dict(self) -> dict[str, Any]:
        """The JSON document described in the module docstring."""
        return {
            "format": FORMAT,
            "version": VERSION,
            "task": self.task,
            "dims": list(self.dims),
            "rate_hz": self.rate_hz,
            "speed": self.speed,
            "angular_speed": self.angular_speed,
            "n_demos": self.n_demos,
            "exploration": self.exploration.to_dict(),
            "dynamics": None if self.dynamics is None else self.dynamics.to_dict(),
            **(
                {}
                if self.covariance_choice is None
                else {"covariance_choice": self.covariance_choice.to_dict()}
            ),
        }

    def save(self, path: str | Path) -> Path:
        """Write the model as JSON; returns the path."""
        path = Path(path)
        return atomic_write_text(path, json.dumps(self.to_dict(), indent=1), "model file")

    @classmethod
    def from_dict(
        cls, doc: Any, *, task: str | None = None, dims: Sequence[str] | None = None
    ) -> SearchModel:
        """Build from a parsed document, checking format, version, task and dims."""
        if not isinstance(doc, dict) or doc.get("format") != FORMAT:
            raise ModelError(f"not a search model (format field must be {FORMAT!r})")
        if doc.get("version") != VERSION:
            raise ModelError(f"unsupported search model version {doc.get('version')!r}")
        try:
            got_dims = tuple(doc["dims"])
            if task is not None and doc["task"] != task:
                raise ModelError(f"model was learned for task {doc['task']!r}, not {task!r}")
            if dims is not None and got_dims != tuple(dims):
                raise ModelError(f"model has dims {got_dims}, expected {tuple(dims)}")
            dyn = doc["dynamics"]
            return cls(
                task=str(doc["task"]),
                dims=got_dims,
                exploration=ExplorationDistribution.from_dict(doc["exploration"]),
                dynamics=None if dyn is None else DynamicsModel.from_dict(dyn),
                rate_hz=float(doc["rate_hz"]),
                speed=float(doc["speed"]),
                angular_speed=None if doc["angular_speed"] is None else float(doc["angular_speed"]),
                n_demos=int(doc["n_demos"]),
                covariance_choice=(
                    None
                    if doc.get("covariance_choice") is None
                    else CovarianceChoice.from_dict(doc["covariance_choice"])
                ),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ModelError(f"invalid search model document: {exc!r}") from exc

    @classmethod
    def load(
        cls, path: str | Path, *, task: str | None = None, dims: Sequence[str] | None = None
    ) -> SearchModel:
        """Read a model written by :meth:`save`.

        Raises ModelError if the file is missing, not JSON, another format or version, or was
        learned for another ``task`` or ``dims`` than requested.
        """
        path = Path(path)
        try:
            doc = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            raise ModelError(f"cannot read search model {path}: {exc}") from exc
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise ModelError(
                f"{path} is not a search model (a JSON file written by 'teachfit learn search')"
            ) from exc
        try:
            return cls.from_dict(doc, task=task, dims=dims)
        except ModelError as exc:
            raise ModelError(f"{path}: {exc}") from exc
