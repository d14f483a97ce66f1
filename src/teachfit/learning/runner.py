"""Run a study's trials in parallel worker processes until its budget is used.

Trials run in a :class:`concurrent.futures.ProcessPoolExecutor` (default: one worker per core)
or, with ``workers=0``, in this process. Each finished trial is stored at once
(:meth:`~teachfit.learning.study.Study.tell`). Faults end the trial, not the study:

* the objective raises, or returns a non-finite cost (a diverging simulation): the trial is
  stored as failed with the study's penalty cost;
* a worker process dies (segfault, ``os._exit``, out of memory): the pool breaks and every
  trial running in it is lost. If only one was running, it is the culprit and fails; else the
  lost trials are re-run one at a time in a fresh pool, which finds the culprit and completes
  the innocent ones (they had not finished, so nothing is repeated).

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

import ctypes
import ctypes.util
import math
import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Callable, Mapping
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from typing import Any

from teachfit.core.params import LearningError
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

    @property
    def trials_per_s(self) -> float:
        return self.finished / self.wall_s if self.wall_s > 0 else math.nan


def _as_result(value: object) -> TrialResult:
    if isinstance(value, TrialResult):
        return value
    if isinstance(value, tuple) and len(value) == 2:
        return TrialResult(float(value[0]), bool(value[1]))
    return TrialResult(float(value))  # type: ignore[arg-type]


def evaluate(objective: Objective, params: Mapping[str, float]) -> tuple[TrialResult | None, str]:
    """Run one trial; ``(result, "")`` or ``(None, error message)``. Runs in a worker."""
    try:
        result = _as_result(objective(params))
    except Exception as exc:  # any failure of the trial is that trial's, not the study's
        return None, f"{type(exc).__name__}: {exc}"
    if not math.isfinite(result.cost):
        return None, f"non-finite cost {result.cost} (diverged)"
    return result, ""


#: seconds between looks at a study while only other processes run its trials
POLL_S = 0.5

_PR_SET_PDEATHSIG = 1


def die_with_parent(parent: int | None = None) -> bool:
    """Have the kernel SIGKILL this process when its parent dies (Linux ``prctl``); exit at
    once if ``parent`` (the expected parent PID) is already gone. False where unsupported."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        ok = libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
    except (OSError, AttributeError):
        ok = False
    if parent is not None and os.getppid() != parent:
        os._exit(1)  # the parent died before the request took effect
    return ok


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
    this process (no crash isolation). Stops early if the learner has nothing left to ask.
    ``on_trial(record)`` is called in this process after each trial is stored (progress).
    """
    if budget < 0:
        raise LearningError(f"budget must be >= 0, got {budget}")
    n_workers = (os.cpu_count() or 1) if workers is None else int(workers)
    if n_workers < 0:
        raise LearningError(f"workers must be >= 0, got {workers}")
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
    )


def _run_pool(
    study: Study,
    objective: Objective,
    budget: int,
    n_workers: int,
    sig: Interrupts,
    store: Callable[[Candidate, TrialResult | None, str], None],
    mp_context: str | None,
) -> None:
    ctx = multiprocessing.get_context(mp_context) if mp_context else None
    method = (ctx or multiprocessing).get_start_method()
    parent = os.getpid() if method in ("fork", "spawn") else None  # forkserver: not us

    def new_pool() -> ProcessPoolExecutor:
        return ProcessPoolExecutor(
            n_workers, mp_context=ctx, initializer=_worker_init, initargs=(parent,)
        )

    pool = new_pool()
    pending: dict[Future[tuple[TrialResult | None, str]], Candidate] = {}
    suspects: list[Candidate] = []  # trials lost in a broken pool, re-run one at a time
    retry: list[Candidate] = []  # asked but never started (submitted to a broken pool)
    try:
        while True:
            while not sig.stop:
                if suspects:
                    if pending:
                        break
                    cand: Candidate | None = suspects.pop(0)
                elif retry:
                    cand = retry.pop(0)
                else:
                    if len(pending) >= n_workers:
                        break
                    # None: a population waits for its tells, the budget is taken, or exhausted
                    cand = study.ask(budget)
                    if cand is None:
                        break
                try:
                    fut = pool.submit(evaluate, objective, study.params_of(cand))
                except BrokenProcessPool:  # broke before we saw it: submit it again later
                    retry.insert(0, cand)
                    break
                pending[fut] = cand
                if suspects or len(pending) >= n_workers:
                    break
            if not pending:
                if sig.stop:
                    break
                if suspects or retry:
                    continue
                if study.settled(budget):
                    break  # budget used, or the learner has nothing more to ask
                time.sleep(POLL_S)  # other processes run trials this learner waits for
                continue
            done, _ = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
            broken: list[Candidate] = []
            for fut in done:
                cand = pending.pop(fut)
                try:
                    result, error = fut.result()
                except BrokenProcessPool:
                    broken.append(cand)
                    continue
                store(cand, result, error)
            if broken:
                # every other running trial is lost with the pool: collect them too
                for fut, cand in list(pending.items()):
                    try:
                        result, error = fut.result()
                        store(cand, result, error)
                    except BrokenProcessPool:
                        broken.append(cand)
                pending.clear()
                pool.shutdown(wait=True)
                pool = new_pool()
                if len(broken) == 1:
                    store(broken[0], None, "worker process crashed")
                else:
                    suspects = broken + suspects
    except BaseException:
        _kill_pool(pool)
        raise
    pool.shutdown(wait=True)
