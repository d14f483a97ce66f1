"""A learning study: every finished trial stored at once in an Optuna storage, resumable.

The storage is any SQLAlchemy URL Optuna accepts, or a file path meaning
``sqlite:///<path>``. A study is tagged (Optuna study user attributes) with the task and skill
names, the method, its seed and options, the parameter space and the failure penalty; opening a
stored study with other tags is a :class:`StudyMismatchError` naming what differs.

Each finished trial is written with :meth:`optuna.study.Study.add_trial` the moment it is told
(one committed transaction), with its physical parameters, cost, and as user attributes the
learner's candidate ``key``, its unit-cube point ``u``, ``feasible``, ``outcome`` and any error.
Opening a study rebuilds a fresh learner with the stored seed and options and replays the
stored trials into it (:meth:`~teachfit.learning.base.Learner.restore`): a killed run resumes
where it stopped, finished trials are neither lost nor asked again, and trials that were running
when it was killed are asked anew.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import optuna
from optuna.distributions import FloatDistribution

from teachfit.core.params import LearningError, ParamSpace
from teachfit.learning.base import Candidate, Finished, Learner, TrialResult
from teachfit.learning.bo import BayesOpt
from teachfit.learning.cmaes import CMAES
from teachfit.learning.lhs import LatinHypercube
from teachfit.learning.pso import PSO

METHODS = ("cmaes", "pso", "bo", "lhs")


class StudyMismatchError(LearningError):
    """A stored study belongs to another task, skill, method or parameter space."""


def make_learner(
    method: str, space: ParamSpace, seed: int = 0, options: Mapping[str, Any] | None = None
) -> Learner:
    """A fresh learner by name (``cmaes``, ``pso``, ``bo``, ``lhs``) with JSON-able options.

    ``lhs`` needs ``n`` (design size); ``bo`` accepts ``sampler="tpe"`` to stand in for the GP.
    """
    opts = dict(options or {})
    try:
        if method == "cmaes":
            return CMAES(space, seed=seed, **opts)
        if method == "pso":
            return PSO(space, seed=seed, **opts)
        if method == "lhs":
            return LatinHypercube(space, seed=seed, **opts)
        if method == "bo":
            if opts.pop("sampler", "gp") == "tpe":
                opts["sampler"] = optuna.samplers.TPESampler(seed=seed)
            return BayesOpt(space, seed=seed, **opts)
    except TypeError as exc:
        raise LearningError(f"bad options for {method}: {exc}") from exc
    raise LearningError(f"unknown learning method {method!r}; known: {list(METHODS)}")


def storage_url(storage: str | Path) -> str:
    """An SQLAlchemy URL as is; anything else is a file path for an SQLite database."""
    text = str(storage)
    if "://" in text:
        return text
    path = Path(text).expanduser().resolve()
    path.parent.mkdir(parents=True, exist_ok=True)
    return f"sqlite:///{path}"


def stored_tags(storage: str | Path, name: str = "teachfit") -> dict[str, Any] | None:
    """The tags of study ``name`` in ``storage`` (task, skill, method, options, ...), or
    ``None`` if there is no such study."""
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    if "://" not in str(storage) and not Path(storage).expanduser().exists():
        return None  # a file that does not exist yet holds no study: do not create it here
    try:
        study = optuna.load_study(study_name=name, storage=storage_url(storage))
    except KeyError:
        return None
    return dict(study.user_attrs)


@dataclass(frozen=True)
class TrialRecord:
    """A stored finished trial; ``number`` counts finished trials from 0 in finishing order."""

    number: int
    key: str
    params: dict[str, float]
    cost: float
    feasible: bool
    outcome: str
    error: str
    info: dict[str, float] = field(default_factory=dict)


class Study:
    """Open (create or resume) a tagged study and its learner.

    Parameters
    ----------
    storage : str or Path
        SQLAlchemy URL or SQLite file path.
    task, skill : str
        Names the study is tagged with.
    space : ParamSpace
    method : str
        One of :data:`METHODS`; ``options`` (JSON-able) go to its constructor.
    seed : int
    penalty : float
        Cost told for a trial that crashed, raised or diverged (s, like the cost).
    name : str
        Study name within the storage.
    resume : bool
        Allow opening a study that already has trials (else :class:`LearningError`).
    context : mapping or None
        More JSON-able tags that must match on resume (e.g. controller, set-up seed).
    """

    def __init__(
        self,
        storage: str | Path,
        *,
        task: str,
        skill: str,
        space: ParamSpace,
        method: str,
        seed: int = 0,
        options: Mapping[str, Any] | None = None,
        penalty: float = 1000.0,
        name: str = "teachfit",
        resume: bool = True,
        context: Mapping[str, Any] | None = None,
    ) -> None:
        if not math.isfinite(penalty):
            raise LearningError(f"penalty must be finite, got {penalty}")
        self.url = storage_url(storage)
        self.space = space
        self.penalty = float(penalty)
        tags: dict[str, Any] = {
            "task": task,
            "skill": skill,
            "method": method,
            "seed": int(seed),
            "options": dict(options or {}),
            "space": space.to_json(),
            "penalty": self.penalty,
        }
        if context:
            tags["context"] = dict(context)
        self.tags = tags
        optuna.logging.set_verbosity(optuna.logging.WARNING)
        self.learner = make_learner(method, space, seed, options)
        self._optuna = optuna.create_study(
            storage=self.url, study_name=name, direction="minimize", load_if_exists=True
        )
        stored = self._optuna.user_attrs
        if not stored:
            for k, v in tags.items():
                self._optuna.set_user_attr(k, v)
        else:
            diff = [k for k in tags if stored.get(k) != tags[k]]
            if diff:
                what = "; ".join(f"{k}: stored {stored.get(k)!r}, asked {tags[k]!r}" for k in diff)
                raise StudyMismatchError(f"study {name!r} in {self.url} differs: {what}")
        self._dists = {
            n: FloatDistribution(d.low, d.high, log=d.log) for n, d in space.domains.items()
        }
        finished = self._finished_trials()
        if finished and not resume:
            raise LearningError(
                f"study {name!r} in {self.url} already has {len(finished)} trials: resume it "
                "(--resume) or choose another study"
            )
        self.learner.restore(
            [
                Finished(
                    Candidate(t.user_attrs["key"], tuple(t.user_attrs["u"])),
                    float(t.value),  # type: ignore[arg-type]
                    bool(t.user_attrs["feasible"]),
                )
                for t in finished
            ]
        )
        self.n_restored = len(finished)
        self._n = len(finished)

    def _finished_trials(self) -> list[optuna.trial.FrozenTrial]:
        trials = self._optuna.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
        return sorted(trials, key=lambda t: t.number)

    # ------------------------------------------------------------------------- trials
    @property
    def n_finished(self) -> int:
        """Finished trials stored so far (restored ones included)."""
        return self._n

    def ask(self) -> Candidate | None:
        """The learner's next candidate (``None``: wait for pending tells, or exhausted)."""
        return self.learner.ask()

    def params_of(self, candidate: Candidate) -> dict[str, float]:
        """Physical parameter values of a candidate."""
        return self.space.from_unit(candidate.u)

    def tell(
        self, candidate: Candidate, result: TrialResult | None, error: str = ""
    ) -> TrialRecord:
        """Store a finished trial at once, then tell the learner.

        ``result=None`` (or a non-finite cost) records a failed trial at the study's penalty.
        """
        if result is None or not math.isfinite(result.cost):
            cost, feasible = self.penalty, False
            outcome = "error"
            error = error or "non-finite cost"
            info: dict[str, float] = {}
        else:
            cost, feasible = float(result.cost), bool(result.feasible)
            outcome = "ok" if feasible else "infeasible"
            info = {k: float(v) for k, v in result.info.items()}
        params = self.params_of(candidate)
        frozen = optuna.trial.create_trial(
            params=params,
            distributions=self._dists,
            value=cost,
            user_attrs={
                "key": candidate.key,
                "u": list(candidate.u),
                "feasible": feasible,
                "outcome": outcome,
                "error": error,
                "info": info,
            },
        )
        self._optuna.add_trial(frozen)  # committed before the learner hears of it
        self._n += 1
        self.learner.tell(candidate, cost, feasible)
        return TrialRecord(self._n - 1, candidate.key, params, cost, feasible, outcome, error, info)

    def trials(self) -> list[TrialRecord]:
        """All stored finished trials, in the order they finished."""
        return [
            TrialRecord(
                i,
                t.user_attrs["key"],
                dict(t.params),
                float(t.value),  # type: ignore[arg-type]
                bool(t.user_attrs["feasible"]),
                str(t.user_attrs["outcome"]),
                str(t.user_attrs["error"]),
                {k: float(v) for k, v in (t.user_attrs.get("info") or {}).items()},
            )
            for i, t in enumerate(self._finished_trials())
        ]

    def best(self) -> TrialRecord:
        """The cheapest feasible trial (any trial if none is feasible)."""
        recs = self.trials()
        if not recs:
            raise LearningError("the study has no finished trial yet")
        feasible = [r for r in recs if r.feasible] or recs
        return min(feasible, key=lambda r: r.cost)
