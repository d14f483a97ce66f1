"""A learning study: every finished trial stored at once in an Optuna storage, resumable.

The storage is a database URL (SQLite, PostgreSQL or MySQL) or a file path meaning an SQLite
database at exactly that name (:mod:`teachfit.learning.storage`). A study is tagged (Optuna
study user attributes) with the task and skill names, the method, its seed and options, the
parameter space and the failure penalty; opening a stored study with other tags is a
:class:`StudyMismatchError` naming what differs.

Each finished trial is written with :meth:`optuna.study.Study.add_trial` the moment it is told
(one committed transaction), with its physical parameters, cost, and as user attributes the
learner's candidate ``key``, its unit-cube point ``u``, ``feasible``, ``outcome`` and any error.
Opening a study rebuilds a fresh learner with the stored seed and options and replays the
stored trials into it (:meth:`~teachfit.learning.base.Learner.restore`): a killed run resumes
where it stopped, finished trials are neither lost nor asked again, and trials that were running
when it was killed are asked anew.

Any number of processes, on one machine or several, may work on one study at once (SQLite on a
local disk, or a database server such as PostgreSQL). Each key a learner asks is *claimed*
(:mod:`teachfit.learning.claims`) before it runs, within the trial budget: a key runs in one
process only, keys of a process that died are taken over by the others, and trials finished
elsewhere are told to this process's learner (:meth:`~teachfit.learning.base.Learner.adopt`)
when it syncs -- so a CMA-ES generation is shared out among the processes, and all of them
together finish exactly the budget, each key once.
"""

from __future__ import annotations

import math
import time
import weakref
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import optuna
from optuna.distributions import BaseDistribution, FloatDistribution
from optuna.exceptions import StorageInternalError
from sqlalchemy.exc import DBAPIError

from teachfit.core.params import LearningError, ParamSpace
from teachfit.learning.base import Candidate, Finished, Learner, TrialResult
from teachfit.learning.bo import BayesOpt
from teachfit.learning.claims import (
    Claim,
    Claims,
    Verdict,
    engine_kwargs,
    release_dropped,
    serialise_sqlite,
)
from teachfit.learning.cmaes import CMAES
from teachfit.learning.lhs import LatinHypercube
from teachfit.learning.pso import PSO
from teachfit.learning.storage import is_url, shown, storage_url

METHODS = ("cmaes", "pso", "bo", "lhs")

#: seconds between reads of what other processes sharing a study have finished
SYNC_S = 1.0

T = TypeVar("T")


#: SQLite's words for a file that no retry will make readable
_BROKEN = ("malformed", "not a database", "file is encrypted")


def _retry(fn: Callable[[], T], attempts: int = 8, what: str = "study database") -> T:
    """``fn()``, retried on database errors: processes creating one study's tables race.
    A damaged database, or errors that outlast the retries, are a :class:`LearningError`."""
    for i in range(attempts):
        try:
            return fn()
        except (DBAPIError, StorageInternalError) as exc:
            cause = getattr(exc, "orig", None) or exc.__cause__ or exc
            text = (str(cause).strip().splitlines() or [type(cause).__name__])[0]
            if i == attempts - 1 or any(word in text for word in _BROKEN):
                raise LearningError(f"{what}: {text}") from exc
            time.sleep(0.05 * 2**i)
    raise AssertionError("unreachable")


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


def stored_tags(storage: str | Path, name: str = "teachfit") -> dict[str, Any] | None:
    """The tags of study ``name`` in ``storage`` (task, skill, method, options, ...), or
    ``None`` if there is no such study."""
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    if not is_url(storage) and not Path(storage).expanduser().exists():
        return None  # a file that does not exist yet holds no study: do not create it here
    try:
        study = _retry(
            lambda: optuna.load_study(study_name=name, storage=storage_url(storage)),
            what=f"study database {storage}",
        )
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


def _study_tags(
    task: str,
    skill: str,
    method: str,
    seed: int,
    options: Mapping[str, Any] | None,
    space: ParamSpace,
    penalty: float,
    context: Mapping[str, Any] | None,
) -> dict[str, Any]:
    """The tags a study is stored with and must match on resume."""
    tags: dict[str, Any] = {
        "task": task,
        "skill": skill,
        "method": method,
        "seed": int(seed),
        "options": dict(options or {}),
        "space": space.to_json(),
        "penalty": penalty,
    }
    if context:
        tags["context"] = dict(context)
    return tags


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
    claim_timeout : float
        Seconds without a heartbeat after which another process's claim counts as dead (a
        process on this machine counts as dead at once when its PID is gone).
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
        claim_timeout: float = 60.0,
    ) -> None:
        if not math.isfinite(penalty):
            raise LearningError(f"penalty must be finite, got {penalty}")
        if not claim_timeout > 0:
            raise LearningError(f"claim_timeout must be > 0 s, got {claim_timeout}")
        release_dropped()  # studies dropped unclosed, before this one reads the claims
        self.url = storage_url(storage)
        #: the storage as a person reads it (a file's path; a URL without its password)
        self.where = shown(self.url)
        self.space = space
        self.penalty = float(penalty)
        self.tags = _study_tags(task, skill, method, seed, options, space, self.penalty, context)
        optuna.logging.set_verbosity(optuna.logging.WARNING)
        self.learner = make_learner(method, space, seed, options)
        self._open_storage(name)
        finished = self._finished_trials()
        self._tag_or_compare(name, bool(finished))
        if finished and not resume:
            raise LearningError(
                f"study {name!r} in {self.where} already has {len(finished)} trials: resume it "
                "(--resume) or choose another study"
            )
        self.learner.restore([_finished(t) for t in finished])
        self.n_restored = len(finished)
        #: finished trials this object stored (the others: restored, or stored elsewhere)
        self.n_here = 0
        self._seen = {str(t.user_attrs["key"]) for t in finished}
        self._claims = Claims(self.url, name, claim_timeout)
        weakref.finalize(self, self._claims.drop)
        self._running: dict[str, tuple[Candidate, bool]] = {}  # claimed here: (cand, own)
        self._retry: list[tuple[Candidate, bool]] = []  # to claim (again)
        self._elsewhere: dict[str, Candidate] = {}  # claimed by other processes
        self._others = 0  # live claims of other processes, unfinished
        self._synced = time.monotonic()

    def _open_storage(self, name: str) -> None:
        """Connect to the storage and create (or load) the Optuna study ``name`` in it."""
        what = f"study database {self.where}"
        rdb = _retry(
            lambda: optuna.storages.RDBStorage(self.url, engine_kwargs=engine_kwargs(self.url)),
            what=what,
        )
        serialise_sqlite(rdb.engine)
        self._rdb = rdb
        self._optuna = _retry(
            lambda: optuna.create_study(
                storage=rdb, study_name=name, direction="minimize", load_if_exists=True
            ),
            what=what,
        )
        self._dists: dict[str, BaseDistribution] = {
            n: FloatDistribution(d.low, d.high, log=d.log) for n, d in self.space.domains.items()
        }
        #: SQLite: id of the last trial read (-1: none yet); None: read all every time
        self._read_above: int | None = -1 if self.url.startswith("sqlite") else None
        self._read: list[optuna.trial.FrozenTrial] = []

    def _tag_or_compare(self, name: str, has_trials: bool) -> None:
        """Tag a study without trials with the tags it lacks, then compare the stored tags
        with :attr:`tags`: a difference is a :class:`StudyMismatchError`."""
        tags = self.tags
        stored = self._optuna.user_attrs
        if not has_trials:
            # a new study, maybe being tagged by another process at this moment: add the
            # tags it lacks (one at a time, like that process), then compare them all
            for k, v in tags.items():
                if k not in stored:
                    self._optuna.set_user_attr(k, v)
            stored = self._optuna.user_attrs
        diff = [k for k in tags if stored.get(k) != tags[k]]
        if diff:
            what = "; ".join(f"{k}: stored {stored.get(k)!r}, asked {tags[k]!r}" for k in diff)
            raise StudyMismatchError(f"study {name!r} in {self.where} differs: {what}")

    def _finished_trials(self) -> list[optuna.trial.FrozenTrial]:
        # read the database itself, not Optuna's cache of it: the cache skips trials that
        # other processes commit out of id order (concurrent writers of a database server)
        sid = self._optuna._study_id
        complete = optuna.trial.TrialState.COMPLETE
        if self._read_above is None:
            trials = _retry(
                lambda: self._rdb.get_all_trials(sid, deepcopy=False, states=(complete,))
            )
            return sorted(trials, key=lambda t: (t.number, t._trial_id))
        # SQLite serialises its writers (BEGIN IMMEDIATE) and trials are stored finished, so
        # trial ids become visible in order: read only those above the last one seen. (A full
        # read costs ~1 ms per stored trial, once a second: ~15 % of a learning run's CPU.)
        above = self._read_above
        new = _retry(lambda: self._rdb._get_trials(sid, None, set(), above))
        if any(t.state != complete for t in new):  # written by something else: read it all
            self._read_above, self._read = None, []
            return self._finished_trials()
        if new:
            self._read_above = max(t._trial_id for t in new)
            self._read = sorted([*self._read, *new], key=lambda t: (t.number, t._trial_id))
        return list(self._read)

    # ------------------------------------------------------------------------- trials
    @property
    def n_finished(self) -> int:
        """Finished trials in the study as last seen (restored, stored here or elsewhere)."""
        return len(self._seen)

    def ask(self, budget: int | None = None) -> Candidate | None:
        """Claim and return the next candidate, or ``None`` if none can be claimed now: the
        learner waits for trials running (here or elsewhere), the budget is taken by finished
        and running trials, or the learner is exhausted (:meth:`settled` tells which)."""
        release_dropped()  # studies dropped unclosed: outside any transaction, here
        if time.monotonic() - self._synced > SYNC_S:
            self.sync()
        cand = self._next(budget)
        if cand is None and (self._elsewhere or not self._running):
            self.sync()  # trials finished elsewhere may let the learner go on
            cand = self._next(budget)
        return cand

    def _next(self, budget: int | None) -> Candidate | None:
        while True:
            if self._retry:
                cand, own = self._retry.pop(0)
            else:
                asked = self.learner.ask()
                if asked is None:
                    return None
                cand, own = asked, True
            verdict, dead = self._claims.claim(cand.key, cand.u, budget, self._seen)
            if verdict is Verdict.MINE:
                if dead is not None and not own:
                    cand = Candidate(cand.key, dead.u)  # the point the dead process ran
                self._running[cand.key] = (cand, own)
                return cand
            if verdict is Verdict.BUDGET:
                self._retry.insert(0, (cand, own))
                return None
            other = self.learner.release(cand) if own else None
            if other is not None:
                self._retry.insert(0, (other, True))
            else:
                self._elsewhere[cand.key] = cand

    def sync(self) -> None:
        """Read what other processes finished (told to the learner) and which of their
        claims died (their keys are claimed again by :meth:`ask`)."""
        self._synced = time.monotonic()
        me, timeout, now = self._claims.owner, self._claims.timeout, time.time()
        claims = {c.key: c for c in _retry(self._claims.all)}
        dead: dict[str, Claim] = {
            k: c for k, c in claims.items() if c.owner != me and not c.alive(timeout, now)
        }
        finished = self._finished_trials()  # read after the owners were seen dead
        stored = {str(t.user_attrs["key"]) for t in finished}
        storing = [c for c in dead.values() if c.state == "storing"]
        if storing:
            self._claims.resolve(storing, stored)
        for t in finished:
            key = str(t.user_attrs["key"])
            if key in self._seen:
                continue
            self._seen.add(key)
            self._elsewhere.pop(key, None)
            if key not in self._running:
                self.learner.adopt(_finished(t))
        for key, cand in list(self._elsewhere.items()):
            c = claims.get(key)
            if c is None or (key in dead and key not in stored):
                del self._elsewhere[key]  # released, or its process died: claim it again
                self._retry.append((cand, False))
        self._others = sum(
            1
            for k, c in claims.items()
            if c.owner != me and c.state != "done" and k not in dead and k not in stored
        )

    def settled(self, budget: int | None = None) -> bool:
        """Right after :meth:`ask` returned ``None`` with nothing running here (it has just
        synced and asked again): ``True`` if this process has nothing more to do (the study
        holds ``budget`` trials, or the learner is exhausted and no other process runs a
        trial), ``False`` if it should wait for other processes (their trials may let the
        learner go on, or their process may die) and ask again."""
        if budget is not None and self.n_finished >= budget:
            return True
        if self._retry:
            return False
        return self._others == 0

    def params_of(self, candidate: Candidate) -> dict[str, float]:
        """Physical parameter values of a candidate."""
        return self.space.from_unit(candidate.u)

    def tell(
        self, candidate: Candidate, result: TrialResult | None, error: str = ""
    ) -> TrialRecord | None:
        """Store a finished trial at once, then tell the learner.

        ``result=None`` (or a non-finite cost) records a failed trial at the study's penalty.
        Returns ``None`` (and stores nothing) if this process lost the candidate's claim to
        another one (after missing heartbeats for ``claim_timeout``).
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
        key = candidate.key
        _, own = self._running.pop(key, (candidate, True))
        if not self._claims.begin_store(key):
            other = self.learner.release(candidate) if own else None
            if other is not None:
                self._retry.append((other, True))
            else:
                self._elsewhere[key] = candidate
            return None
        params = self.params_of(candidate)
        frozen = optuna.trial.create_trial(
            params=params,
            distributions=self._dists,
            value=cost,
            user_attrs={
                "key": key,
                "u": list(candidate.u),
                "feasible": feasible,
                "outcome": outcome,
                "error": error,
                "info": info,
            },
        )
        _retry(lambda: self._optuna.add_trial(frozen))  # committed before the learner hears
        self._claims.end_store(key)
        self._seen.add(key)
        self.n_here += 1
        if own:
            self.learner.tell(candidate, cost, feasible)
        else:
            self.learner.adopt(Finished(candidate, cost, feasible))
        return TrialRecord(self.n_finished - 1, key, params, cost, feasible, outcome, error, info)

    def abandon(self) -> None:
        """Give up the trials running here (an aborted run): other processes may claim them."""
        self._running.clear()
        self._claims.release()

    def close(self) -> None:
        """Release this process's unfinished claims and its database connections."""
        self._running.clear()
        self._claims.close()

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


def _finished(t: optuna.trial.FrozenTrial) -> Finished:
    return Finished(
        Candidate(str(t.user_attrs["key"]), tuple(float(x) for x in t.user_attrs["u"])),
        float(t.value),  # type: ignore[arg-type]
        bool(t.user_attrs["feasible"]),
    )
