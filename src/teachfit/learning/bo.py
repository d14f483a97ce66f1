"""Bayesian optimisation through Optuna's GP sampler, behind the ask/tell interface.

``optuna.samplers.GPSampler`` fits a Gaussian process (Matern 5/2 kernel with automatic
relevance determination, as in the paper's spearmint set-up) and maximises log expected
improvement, batch-aware (qLogEI) for trials still running in other workers. Failed trials are
handled as *constraints* (Optuna's constrained EI: one constraint, ``> 0`` when the trial
failed), so the GP learns where failures are rather than fitting penalty costs alone; the
penalty cost is still told as the objective value. The GP sampler needs PyTorch; without it,
construction raises :class:`~teachfit.learning.base.LearningError` unless another Optuna
sampler is passed in.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Iterator, Sequence
from contextlib import contextmanager, nullcontext

import optuna
from optuna.distributions import BaseDistribution, FloatDistribution

from teachfit.core.params import LearningError, ParamSpace
from teachfit.learning.base import Candidate, Finished

_CONSTRAINT = "failure"


#: BLAS / OpenMP thread limits (threadpoolctl comes with scikit-learn; no type information)
threadpool_limits = importlib.import_module("threadpoolctl").threadpool_limits


@contextmanager
def _one_thread() -> Iterator[None]:
    """PyTorch, BLAS and OpenMP on one thread while the GP is fitted and the acquisition
    maximised: its tensors and matrices (at most a few hundred trials x 15 parameters) are too
    small to share out. Measured on the 2-core machine, identical candidates: PyTorch on two
    threads took 1.3 x the CPU time of one (85 vs 64 CPU-s for 70 asks); OpenBLAS's second
    thread, which spins while it waits, 1.8 x idle and 3.2 x beside two busy processes (60 asks:
    9.9 vs 5.6 CPU-s, and 19.9 vs 6.3 CPU-s, 20.6 vs 9.1 s wall), CPU the trials' workers
    need."""
    # imported here when not yet (the sampler imports it on its first GP step)
    import torch  # noqa: PLC0415

    before = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        with threadpool_limits(1):
            yield
    finally:
        torch.set_num_threads(before)


class BayesOpt:
    """Bayesian optimisation learner.

    Parameters
    ----------
    space : ParamSpace
    seed : int
    n_startup : int
        Trials sampled independently at random before the GP takes over.
    constraints : bool
        Model failures as a constraint (default) or only through their penalty cost.
    sampler : optuna.samplers.BaseSampler or None
        Override the sampler (tests, or a machine without PyTorch); ``None`` = ``GPSampler``.
    """

    def __init__(
        self,
        space: ParamSpace,
        seed: int = 0,
        n_startup: int = 10,
        constraints: bool = True,
        sampler: optuna.samplers.BaseSampler | None = None,
    ) -> None:
        if n_startup < 1:
            raise LearningError(f"n_startup must be >= 1, got {n_startup}")
        self._gp = sampler is None
        if sampler is None:
            if importlib.util.find_spec("torch") is None:
                raise LearningError(
                    "Bayesian optimisation uses Optuna's GPSampler, which needs PyTorch: "
                    "install torch (CPU build) or choose another method"
                )
            sampler = optuna.samplers.GPSampler(
                seed=seed, n_startup_trials=n_startup, warn_independent_sampling=False
            )
        self.space = space
        self.constraints = constraints
        optuna.logging.set_verbosity(optuna.logging.WARNING)
        self._study = optuna.create_study(direction="minimize", sampler=sampler)
        # the sampler sees unit-cube coordinates u0..u{d-1}; log scales live in the space
        self._dists: dict[str, BaseDistribution] = {
            f"u{i}": FloatDistribution(0.0, 1.0) for i in range(space.dim)
        }
        self._running: dict[str, optuna.trial.Trial] = {}
        self._known: set[str] = set()
        self._counter = 0

    def _new_key(self) -> str:
        while f"b{self._counter}" in self._known:
            self._counter += 1
        key = f"b{self._counter}"
        self._counter += 1
        self._known.add(key)
        return key

    def ask(self) -> Candidate | None:
        with _one_thread() if self._gp else nullcontext():
            trial = self._study.ask(self._dists)
        key = self._new_key()
        self._running[key] = trial
        return Candidate.of(key, [trial.params[f"u{i}"] for i in range(self.space.dim)])

    def release(self, candidate: Candidate) -> Candidate | None:
        trial = self._running.pop(candidate.key, None)
        if trial is None:
            return None
        key = self._new_key()  # keys are names only: the point is still worth a trial
        self._running[key] = trial
        return Candidate(key, candidate.u)

    def adopt(self, finished: Finished) -> None:
        if finished.candidate.key in self._running:
            raise LearningError(f"candidate {finished.candidate.key!r} is pending here")
        self._known.add(finished.candidate.key)
        self._add(finished)

    def tell(self, candidate: Candidate, cost: float, feasible: bool = True) -> None:
        trial = self._running.pop(candidate.key, None)
        if trial is None:
            raise LearningError(f"candidate {candidate.key!r} is not pending")
        if self.constraints:
            trial.set_constraint(_CONSTRAINT, 0.0 if feasible else 1.0)
        self._study.tell(trial, float(cost))

    def restore(self, finished: Sequence[Finished]) -> None:
        if self._running or len(self._study.trials):
            raise LearningError("restore() needs a fresh learner")
        for f in finished:
            self._known.add(f.candidate.key)
            self._add(f)

    def _add(self, f: Finished) -> None:
        self._study.add_trial(
            optuna.trial.create_trial(
                params={f"u{i}": float(u) for i, u in enumerate(f.candidate.u)},
                distributions=self._dists,
                value=float(f.cost),
                constraints=(
                    {_CONSTRAINT: 0.0 if f.feasible else 1.0} if self.constraints else None
                ),
            )
        )
