"""Run a study's trials in parallel worker processes until its budget is used.

Trials run in a :class:`concurrent.futures.ProcessPoolExecutor` (default: one worker per core)
or, with ``workers=0``, in this process. Each finished trial is stored at once
(:meth:`~teachfit.learning.study.Study.tell`). Faults end the trial, not the study:

* the objective raises, or returns a non-finite cost (a diverging simulation): the trial is
  stored as failed with the study's penalty cost;
* a worker process dies (segfault, ``os._exit``, out of memory, killed): the pool breaks and
  every trial running in it is lost. The pool is replaced (also when a worker died idle, found
  as the next trial is submitted), and the lost trials are re-run one at a time in the fresh
  pool: one that breaks it again, alone, is the culprit and fails; the others complete (they
  had not finished, so nothing is repeated). Their claims stay this process's meanwhile, so
  other processes sharing the study neither wait on them forever nor run them twice.

SIGINT / SIGTERM: the first one stops asking for new trials and lets the running ones finish
and be stored, then :func:`run_study` returns with ``interrupted=True``; a second one aborts at
once (running trials are dropped and asked anew on resume) by raising ``KeyboardInterrupt``.
A ``KeyboardInterrupt`` raised by the objective itself aborts the same way.

Workers die with this process: each sits in its own process group (a Ctrl-C at the terminal
reaches only this process, which decides what it means), has the default SIGINT / SIGTERM
actions (not this process's handlers, inherited through ``fork``), and on Linux asks the kernel
to SIGKILL it when its parent dies (``PR_SET_PDEATHSIG``), so even a ``kill -9`` of this
process leaves no worker behind.

Several processes may run one study together (see :mod:`teachfit.learning.study`): each claims
the keys it runs, and one whose learner waits on trials running elsewhere polls until they
finish (or their process dies and it claims them).
"""

from __future__ import annotations

import logging
import math
import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from typing import Any

from teachfit.core.errors import NeedsAPerson
from teachfit.core.params import LearningError
from teachfit.core.process import die_with_parent
from teachfit.learning.base import Candidate, TrialResult
from teachfit.learning.study import Study, TrialRecord

#: what an objective may return: a cost, ``(cost, feasible)`` or a TrialResult
Objective = Callable[[Mapping[str, float]], "TrialResult | float | tuple[float, bool]"]


@dataclass(frozen=True)
class RunReport:
    """What one :func:`run_study` call did (``wall_s`` in seconds)."""

    restored: int
    finished: int
    failed: int
    interrupted: bool
    wall_s: float
    workers: int = 0  # worker processes used (0: trials ran in this process)

    @property
    def trials_per_s(self) -> float:
        return self.finished / self.wall_s if self.wall_s > 0 else math.nan


def _as_result(value: object) -> TrialResult:
    if isinstance(value, TrialResult):
        return value
    if isinstance(value, tuple) and len(value) == 2:
        return TrialResult(float(value[0]), bool(value[1]))
    return TrialResult(float(value))  # type: ignore[arg-type]  # float() rejects non-numbers


def evaluate(objective: Objective, params: Mapping[str, float]) -> tuple[TrialResult | None, str]:
    """Run one trial; ``(result, "")`` or ``(None, error message)``. Runs in a worker.
    :class:`~teachfit.core.errors.NeedsAPerson` (a real arm's part lost, a reset declined)
    is raised on: it stops the run."""
    try:
        result = _as_result(objective(params))
    except NeedsAPerson:  # the cell, not the trial: the run stops, the trial is not charged
        raise
    except Exception as exc:  # any failure of the trial is that trial's, not the study's
        return None, f"{type(exc).__name__}: {exc}"
    if not math.isfinite(result.cost):
        return None, f"non-finite cost {result.cost} (diverged)"
    return result, ""


#: seconds between looks at a study while only other processes run its trials
POLL_S = 0.5

#: at most this many worker processes per core: more only cost memory and start-up time
WORKERS_PER_CPU = 4

_log = logging.getLogger(__name__)


def cap_workers(requested: int | None, left: int, cpus: int | None = None) -> tuple[int, str]:
    """Worker processes for ``left`` trials still to run: ``requested`` (``None``: one per
    core), but at least 1, at most ``left`` and at most :data:`WORKERS_PER_CPU` per core.
    Returns the count and, when an explicit request was cut for trials to run, a one-line
    note (else "")."""
    cpus = max(cpus or os.cpu_count() or 1, 1)
    wanted = cpus if requested is None else requested
    n = max(1, min(wanted, left, WORKERS_PER_CPU * cpus))
    if requested is None or n >= requested or left <= 0:
        return n, ""
    return n, (
        f"{requested} workers asked: using {n} ({left} trial(s) left, "
        f"{cpus} core(s), at most one worker per trial and {WORKERS_PER_CPU} per core)"
    )


def _worker_init(parent: int | None) -> None:
    # not the parent's handlers (inherited through fork, they ignored a first SIGTERM)
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    # a Ctrl-C at the terminal reaches the foreground group: the main process alone decides
    os.setpgid(0, 0)
    die_with_parent(parent)


class Interrupts:
    """First SIGINT/SIGTERM: ask to stop (``stop``); second: ``KeyboardInterrupt``, once.

    Signals after that one are ignored (the program is already aborting). Nested in an
    outer one (e.g. a command that reports after :func:`run_study`), the inner one is the
    outer one: a second Ctrl-C while the command writes its report still aborts cleanly.
    Handlers are restored when the outermost one exits; inactive outside the main thread.
    """

    _active: Interrupts | None = None

    def __init__(self, enabled: bool = True) -> None:
        self.enabled = enabled and threading.current_thread() is threading.main_thread()
        self.stop = False
        self.aborted = False
        self._old: dict[int, Any] = {}
        self._outer: Interrupts | None = None

    def _handle(self, signum: int, frame: object) -> None:
        if self.aborted:
            return
        if self.stop:
            self.aborted = True
            raise KeyboardInterrupt
        self.stop = True

    def __enter__(self) -> Interrupts:
        if not self.enabled:
            return self
        if Interrupts._active is not None:
            self._outer = Interrupts._active
            return self._outer
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._old[sig] = signal.signal(sig, self._handle)
        Interrupts._active = self
        return self

    def __exit__(self, *exc: object) -> None:
        if self._outer is not None or not self._old:
            self._outer = None
            return
        Interrupts._active = None
        for sig, old in self._old.items():
            signal.signal(sig, old)
        self._old.clear()


def _kill_pool(pool: ProcessPoolExecutor) -> None:
    pool.shutdown(wait=False, cancel_futures=True)
    # the executor has no public way to end running workers; its process table is the only one
    for proc in list((getattr(pool, "_processes", None) or {}).values()):
        proc.terminate()


# Long (> 60 lines) by its docstring, which states the claim protocol; the pool loop is
# _PoolRun.
def run_study(
    study: Study,
    objective: Objective,
    budget: int,
    workers: int | None = None,
    handle_signals: bool = True,
    mp_context: str | None = None,
    on_trial: Callable[[TrialRecord], None] | None = None,
) -> RunReport:
    """Run trials of ``study`` until it holds ``budget`` finished trials (restored included).

    ``objective(params)`` gets physical parameter values and returns a cost, ``(cost,
    feasible)`` or a :class:`TrialResult`; with workers it must be picklable (a module-level
    function or a :func:`functools.partial` of one). ``workers=None``: one per core; ``0``: in
    this process (no crash isolation); never more than the trials left or
    :data:`WORKERS_PER_CPU` per core (:func:`cap_workers`; a cut request is logged as a
    warning). Stops early if the learner has nothing left to ask.
    ``on_trial(record)`` is called in this process after each trial is stored (progress).
    """
    if budget < 0:
        raise LearningError(f"budget must be >= 0, got {budget}")
    n_workers = (os.cpu_count() or 1) if workers is None else int(workers)
    if n_workers < 0:
        raise LearningError(f"workers must be >= 0, got {workers}")
    if n_workers > 0:
        n_workers, note = cap_workers(workers, budget - study.n_finished)
        if note:
            _log.warning(note)  # one line on stderr when nothing else handles the log
    t0 = time.perf_counter()
    restored, here = study.n_finished, study.n_here
    failed = 0

    def store(cand: Candidate, result: TrialResult | None, error: str) -> None:
        nonlocal failed
        rec = study.tell(cand, result, error)
        if rec is None:
            return  # the claim was lost to another process, which runs it
        failed += rec.outcome == "error"
        if on_trial is not None:
            on_trial(rec)

    with Interrupts(handle_signals) as sig:
        try:
            if n_workers == 0:
                while not sig.stop:
                    cand = study.ask(budget)
                    if cand is None:
                        if study.settled(budget):
                            break
                        time.sleep(POLL_S)  # others run trials this learner waits for
                        continue
                    store(cand, *evaluate(objective, study.params_of(cand)))
            else:
                _run_pool(study, objective, budget, n_workers, sig, store, mp_context)
        except BaseException:
            study.abandon()  # other processes may run our unfinished trials at once
            raise
        interrupted = sig.stop
    return RunReport(
        restored=restored,
        finished=study.n_here - here,
        failed=failed,
        interrupted=interrupted,
        wall_s=time.perf_counter() - t0,
        workers=n_workers,
    )


class _PoolRun:
    """Trials of one :func:`run_study` call in a process pool, replaced whenever it breaks."""

    def __init__(
        self,
        study: Study,
        objective: Objective,
        budget: int,
        n_workers: int,
        store: Callable[[Candidate, TrialResult | None, str], None],
        mp_context: str | None,
    ) -> None:
        self.study, self.objective, self.budget, self.n = study, objective, budget, n_workers
        self.store = store
        self.ctx = multiprocessing.get_context(mp_context) if mp_context else None
        method = (self.ctx or multiprocessing).get_start_method()
        self.parent = os.getpid() if method in ("fork", "spawn") else None  # forkserver: not us
        self.pool = self._new_pool()
        self.pending: dict[Future[tuple[TrialResult | None, str]], Candidate] = {}
        self.suspects: list[Candidate] = []  # lost in a broken pool: re-run one at a time
        self.alone: Candidate | None = None  # the suspect running alone in a fresh pool
        self.retry: list[Candidate] = []  # claimed, never started: submit again

    def _new_pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(
            self.n, mp_context=self.ctx, initializer=_worker_init, initargs=(self.parent,)
        )

    def _replace_pool(self) -> None:
        self.pool.shutdown(wait=True)
        self.pool = self._new_pool()

    def _submit(self, cand: Candidate, alone: bool) -> bool:
        try:
            fut = self.pool.submit(evaluate, self.objective, self.study.params_of(cand))
        except BrokenProcessPool:
            # the pool broke before this trial got in (a worker died, maybe idle): it never
            # heals; with nothing running in it replace it now, else the wait() path does
            (self.suspects if alone else self.retry).insert(0, cand)
            if not self.pending:
                self._replace_pool()
            return False
        self.pending[fut] = cand
        if alone:
            self.alone = cand
        return True

    def fill(self, sig: Interrupts) -> None:
        """Submit trials until every worker is busy; a suspect runs alone."""
        while not sig.stop and self.alone is None:
            alone = bool(self.suspects)
            if alone and self.pending:
                return
            if alone:
                cand = self.suspects.pop(0)
            elif len(self.pending) >= self.n:
                return
            elif self.retry:
                cand = self.retry.pop(0)
            else:
                # None: a population waits for its tells, the budget is taken, or exhausted
                asked = self.study.ask(self.budget)
                if asked is None:
                    return
                cand = asked
            if not self._submit(cand, alone):
                return

    def collect(self) -> None:
        """Store the trials that finished within 0.2 s; recover from a broken pool."""
        done, _ = wait(self.pending, timeout=0.2, return_when=FIRST_COMPLETED)
        lost = self._take(done)
        if lost:
            self._recover(lost)

    def _take(self, futures: Iterable[Future[tuple[TrialResult | None, str]]]) -> list[Candidate]:
        """Store the trials of ``futures`` (pending); returns those lost with a broken pool."""
        lost: list[Candidate] = []
        for fut in list(futures):
            cand = self.pending.pop(fut)
            try:
                result, error = fut.result()
            except BrokenProcessPool:
                lost.append(cand)
                continue
            if cand is self.alone:
                self.alone = None
            self.store(cand, result, error)
        return lost

    def _recover(self, lost: list[Candidate]) -> None:
        # every other running trial is lost with the pool (it ends all its workers)
        lost += self._take(self.pending)
        culprit = self.alone if lost == [self.alone] else None
        self.alone = None
        self._replace_pool()
        if culprit is not None:  # it broke a fresh pool, alone, a second time
            self.store(culprit, None, "worker process crashed")
        else:  # the trial that killed its worker is among them, or none (killed from outside)
            self.suspects = lost + self.suspects

    def run(self, sig: Interrupts) -> None:
        while True:
            self.fill(sig)
            if not self.pending:
                if sig.stop:
                    break
                if self.suspects or self.retry:
                    continue
                if self.study.settled(self.budget):
                    break  # budget used, or the learner has nothing more to ask
                time.sleep(POLL_S)  # other processes run trials this learner waits for
                continue
            self.collect()
        if self.suspects or self.retry:
            self.study.abandon()  # claimed here but not run (stopped): others may run them
        self.pool.shutdown(wait=True)


def _run_pool(
    study: Study,
    objective: Objective,
    budget: int,
    n_workers: int,
    sig: Interrupts,
    store: Callable[[Candidate, TrialResult | None, str], None],
    mp_context: str | None,
) -> None:
    run = _PoolRun(study, objective, budget, n_workers, store, mp_context)
    try:
        run.run(sig)
    except BaseException:
        _kill_pool(run.pool)
        raise
