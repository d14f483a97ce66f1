"""Ehlers et al.'s Table I protocol on any task, e.g. a user's mesh task file.

One model from the task's demonstrations (recorded by the seeded blind teacher, or given);
``n_starts`` starts of the task's ``"table1"`` protocol (its teacher starts where it has no
such protocol); TSHIX with ``n_points`` points (a new trajectory per start) and one ergodic
trajectory of about the mean TSHIX length, both with the GMR feed-forward. No paper figures:
the paper ran only its own parts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from teachfit.bench.search import ROBOT, Progress, Row, _jobs, _row
from teachfit.bench.search_jobs import SearchJob, run_jobs
from teachfit.core.errors import TeachfitError
from teachfit.demonstrations.dataset import Demonstration
from teachfit.execution.batch import episode_seed
from teachfit.execution.teacher import BlindTeacher
from teachfit.models.search_model import SearchModel
from teachfit.tasks.registry import load_task


def task_demos(
    task_spec: str, seed: int, n: int = 1, max_attempts: int = 20
) -> list[Demonstration]:
    """``n`` blind-teacher demonstrations of ``task_spec`` (up to ``max_attempts`` tries)."""
    task = load_task(task_spec)
    demos, reasons = BlindTeacher(task, seed=seed, robot=ROBOT[0]).record(
        n, max_attempts=max_attempts
    )
    if len(demos) < n:
        raise TeachfitError(
            f"the blind teacher recorded {len(demos)} of {n} demonstration(s) of {task.name} in "
            f"{max_attempts} tries ({reasons[-1] if reasons else 'no reason'}); pass --demo FILE"
        )
    return demos


def task_jobs(
    task_spec: str, demos: Sequence[Demonstration], seed: int, n_starts: int, n_points: int
) -> list[SearchJob]:
    """The TSHIX jobs of the protocol's ``n_starts`` starts (see the module docstring): the
    ``tshix`` row of :func:`task_table` (:func:`~teachfit.bench.search_jobs.run_jobs`)."""
    task = load_task(task_spec)
    if any(d.task != task.name for d in demos):
        raise TeachfitError(f"the demonstrations are not all of task {task.name!r}")
    model = SearchModel.fit(list(demos), task.name)
    rng = np.random.default_rng(seed + 1)
    names = task.protocol.names
    protocol = "table1" if "table1" in names else "teacher"
    starts = task.protocol.protocol_starts(protocol, n_starts, rng, demos[0].start_pose)
    seeds = [episode_seed(seed, i) for i in range(n_starts)]
    return _jobs(task.name, {}, model, starts, "tshix", n_points, seeds)


def task_table(
    task_spec: str,
    demos: Sequence[Demonstration],
    seed: int = 0,
    n_starts: int = 10,
    n_points: int = 300,
    workers: int | None = None,
    progress: Progress = None,
) -> list[Row]:
    """Rows ``tshix`` and ``ergodic`` on the same starts (see the module docstring)."""
    tshix = task_jobs(task_spec, demos, seed, n_starts, n_points)
    res_t = run_jobs(tshix, workers, progress)
    length = float(np.mean([r.weighted_length for r in res_t]))
    erg = [replace(j, method="ergodic", length=length) for j in tshix]
    res_e = run_jobs(erg, workers, progress)
    return [_row("tshix", res_t, None), _row("ergodic", res_e, None)]
