"""Many executions at once: the one seeding rule, the one order-preserving batch runner, and
:class:`Finished`, what a sequence of executions keeps when something ends it early."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Generic, TypeVar

import numpy as np

from teachfit.core.errors import TeachfitError

J = TypeVar("J")
R = TypeVar("R")


def episode_seed(seed: int, i: int) -> int:
    """The seed of episode ``i`` of a batch run with ``seed``: ``1000 seed + i`` (the rule every
    benchmark, command and the quickstart share, so that their episodes are comparable)."""
    if seed < 0 or i < 0:
        raise TeachfitError(f"seeds must be >= 0, got seed={seed}, episode={i}")
    return 1000 * int(seed) + int(i)


def episode_rng(seed: int, i: int) -> np.random.Generator:
    """A generator for episode ``i`` of a batch run with ``seed`` (see :func:`episode_seed`)."""
    return np.random.default_rng(episode_seed(seed, i))


def _in_order(fn: Callable[[J], R], jobs: Sequence[J], workers: int | None) -> Iterator[R]:
    """``fn(job)`` for each job, in order, as each finishes (see :func:`run_batch`); a job
    that raises, or an interrupt, cancels the jobs not yet started."""
    n = (os.cpu_count() or 1) if workers is None else int(workers)
    if n <= 1 or len(jobs) <= 1:
        for job in jobs:
            yield fn(job)
        return
    pool = ProcessPoolExecutor(min(n, len(jobs)))
    try:
        yield from pool.map(fn, jobs, chunksize=1)
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def run_batch(
    fn: Callable[[J], R],
    jobs: Sequence[J],
    workers: int | None = None,
    progress: Callable[[], None] | None = None,
) -> list[R]:
    """``[fn(job) for job in jobs]`` in order, in ``workers`` processes (``None``: one per
    core; 0 or 1: in this process). ``fn`` and the jobs must be picklable for processes;
    ``progress`` is called after each finished job."""
    finished = run_batch_keeping(fn, jobs, workers, progress)
    if finished.stop is not None:
        raise finished.stop
    return finished.items


def run_batch_keeping(
    fn: Callable[[J], R],
    jobs: Sequence[J],
    workers: int | None = None,
    progress: Callable[[], None] | None = None,
) -> Finished[R]:
    """:func:`run_batch` that keeps, when a job raises or the run is interrupted, the results
    of the jobs before it and the exception that stopped the rest (:class:`Finished`)."""
    finished: Finished[R] = Finished(total=len(jobs))
    with keeping(finished):
        for result in _in_order(fn, jobs, workers):
            finished.add(result)
            if progress:
                progress()
    return finished


@dataclass
class Finished(Generic[R]):
    """The executions of a run that finished, in order, and what ended the run early.

    ``items`` every finished execution (add each as it finishes: :meth:`add`), ``total`` how
    many the run was to have (0: unknown), ``stop`` the exception that ended it early (a lost
    connection, a fault, Ctrl-C's ``KeyboardInterrupt``, SIGTERM's ``SystemExit``, a bug);
    ``None``: the run was not cut short.
    """

    items: list[R] = field(default_factory=list)
    total: int = 0
    stop: BaseException | None = None

    def add(self, item: R) -> None:
        """Keep one finished execution."""
        self.items.append(item)

    @property
    def complete(self) -> bool:
        """Nothing cut the run short."""
        return self.stop is None


@contextmanager
def keeping(finished: Finished[R]) -> Iterator[Finished[R]]:
    """Run the body; whatever exception ends it (``BaseException`` included) is stored in
    ``finished.stop`` instead of propagating, so that the caller still reports and records the
    executions that finished; the caller decides how the run ends (:attr:`Finished.stop`)."""
    try:
        yield finished
    except BaseException as exc:  # noqa: BLE001 - kept for the caller, which re-raises or exits
        finished.stop = exc


def keep_each(
    total: int,
    run: Callable[[Callable[[R], None]], object],
    progress: Callable[[], None] | None = None,
) -> Finished[R]:
    """Call ``run(done)``, a run of ``total`` executions that calls ``done(item)`` as each one
    finishes, and keep every finished item and what ended the run early (:func:`keeping`);
    ``progress`` is called after each item."""
    finished: Finished[R] = Finished(total=total)

    def done(item: R) -> None:
        finished.add(item)
        if progress is not None:
            progress()

    with keeping(finished):
        run(done)
    return finished
