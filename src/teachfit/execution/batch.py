"""Many executions at once: the one seeding rule and the one order-preserving batch runner."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import TypeVar

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


def run_batch(
    fn: Callable[[J], R],
    jobs: Sequence[J],
    workers: int | None = None,
    progress: Callable[[], None] | None = None,
) -> list[R]:
    """``[fn(job) for job in jobs]`` in order, in ``workers`` processes (``None``: one per
    core; 0 or 1: in this process). ``fn`` and the jobs must be picklable for processes;
    ``progress`` is called after each finished job."""
    n = (os.cpu_count() or 1) if workers is None else int(workers)
    if n <= 1 or len(jobs) <= 1:
        out = []
        for job in jobs:
            out.append(fn(job))
            if progress:
                progress()
        return out
    with ProcessPoolExecutor(min(n, len(jobs))) as pool:
        results = []
        for res in pool.map(fn, jobs, chunksize=1):
            results.append(res)
            if progress:
                progress()
        return results
