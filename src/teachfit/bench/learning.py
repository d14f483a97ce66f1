"""Johannsmeier et al.'s learning experiments (Sec. V, Fig. 6) over tasks x methods x experiments.

An *experiment* is one learning run of ``trials`` trials (each: one parameter set, ``n_starts``
executions) with its own seed ``seed + e``: its own hole estimate, start poses, sensor noise
and learner seed. Per task and method the bench reports, over experiments: the best cost
(mean +- sd), the success rate of the best parameters (fraction of their executions that
succeeded), trials until the first feasible one, the final insertion time (best feasible
cost, s), the simulated robot time consumed until the first feasible trial, until the best
one and in all (min; the paper: feasible after a few minutes, optimised in under 20 minutes
on the real robot), and wall time and trials/s on this machine.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from teachfit.bench.learning_table import (
    PAPER_ORDERING,
    ordering,
    paired_markdown,
    to_markdown,
    unsolved_setups,
)
from teachfit.core.params import LearningError
from teachfit.learning.curves import Band, band, best_so_far, first_feasible
from teachfit.learning.launch import method_options
from teachfit.learning.objective import SkillObjective
from teachfit.learning.runner import run_study
from teachfit.learning.study import METHODS, Study, TrialRecord

__all__ = [
    "PAPER_ORDERING",
    "BenchInterrupted",
    "CellStats",
    "Experiment",
    "LearningBench",
    "method_options",
    "ordering",
    "paired_markdown",
    "run_experiment",
    "run_learning_bench",
    "study_path",
    "to_markdown",
    "unsolved_setups",
]


class BenchInterrupted(LearningError):
    """An experiment of the bench was interrupted (SIGINT / SIGTERM) before its budget."""


@dataclass(frozen=True)
class Experiment:
    """One finished learning run; per-trial arrays in finishing order, ``sim_s`` in s."""

    task: str
    method: str
    seed: int
    costs: tuple[float, ...]
    feasible: tuple[bool, ...]
    sim_s: tuple[float, ...]
    success_rate: tuple[float, ...]
    best_params: dict[str, float]
    wall_s: float
    n_starts: int = 1  # executions per trial: starts x set-ups
    #: trials read back from a stored study (not run, nor timed, in this call)
    restored: int = 0
    #: success of each execution of the best parameters on held-out set-ups (none: not run)
    held_out: tuple[bool, ...] = ()

    @staticmethod
    def from_records(
        task: str,
        method: str,
        seed: int,
        recs: Sequence[TrialRecord],
        wall_s: float,
        n_starts: int = 1,
        restored: int = 0,
    ) -> Experiment:
        if not recs:
            raise LearningError(f"{task}/{method} seed {seed}: no trial finished")
        ok = [r for r in recs if r.feasible] or list(recs)
        best = min(ok, key=lambda r: r.cost)
        return Experiment(
            task,
            method,
            seed,
            tuple(r.cost for r in recs),
            tuple(r.feasible for r in recs),
            tuple(r.info.get("sim_s", 0.0) for r in recs),
            tuple(r.info.get("success_rate", 0.0) for r in recs),
            dict(best.params),
            wall_s,
            n_starts,
            restored,
        )

    @property
    def best_index(self) -> int:
        """0-based index of the best trial (feasible ones first)."""
        c = np.where(np.asarray(self.feasible), np.asarray(self.costs), np.inf)
        return int(np.argmin(c)) if np.isfinite(c).any() else int(np.argmin(self.costs))

    @property
    def first_feasible(self) -> int | None:
        return first_feasible(self.feasible)

    @property
    def executions_ok(self) -> int:
        """Executions that succeeded, over all trials."""
        return sum(round(r * self.n_starts) for r in self.success_rate)

    def sim_min_until(self, trial: int | None) -> float:
        """Simulated robot minutes of trials 1..``trial`` (NaN for ``None``)."""
        return math.nan if trial is None else float(sum(self.sim_s[:trial])) / 60.0


@dataclass(frozen=True)
class CellStats:
    """One task x method over its experiments (costs and times in s, robot time in min)."""

    task: str
    method: str
    n: int
    best_cost_mean: float
    best_cost_sd: float
    best_cost_low: float
    best_cost_high: float
    best_success: float
    first_feasible_mean: float
    never_feasible: int
    insertion_time: float
    sim_feasible_min: float
    sim_best_min: float
    sim_total_min: float
    wall_s: float
    trials_per_s: float
    curve: Band = field(repr=False)
    executions_ok: int = 0
    executions: int = 0
    held_out_ok: int = 0
    held_out: int = 0

    @staticmethod
    def of(exps: Sequence[Experiment]) -> CellStats:
        best = np.array([e.costs[e.best_index] for e in exps])
        ok = [e for e in exps if e.first_feasible is not None]
        ins = [e.costs[e.best_index] for e in ok]
        n_trials = sum(len(e.costs) - e.restored for e in exps)  # the ones timed here
        wall = float(np.mean([e.wall_s for e in exps]))
        ci = band([[b] for b in best])  # t interval of the mean best cost over experiments
        return CellStats(
            exps[0].task,
            exps[0].method,
            len(exps),
            float(best.mean()),
            float(best.std(ddof=1)) if len(exps) > 1 else 0.0,
            float(ci.low[0]),
            float(ci.high[0]),
            float(np.mean([e.success_rate[e.best_index] for e in exps])),
            float(np.mean([e.first_feasible for e in ok])) if ok else math.nan,
            len(exps) - len(ok),
            float(np.mean(ins)) if ins else math.nan,
            float(np.mean([e.sim_min_until(e.first_feasible) for e in ok])) if ok else math.nan,
            float(np.mean([e.sim_min_until(e.best_index + 1) for e in exps])),
            float(np.mean([e.sim_min_until(len(e.costs)) for e in exps])),
            wall,
            n_trials / (wall * len(exps)) if wall > 0 else math.nan,
            band([best_so_far(e.costs) for e in exps]),
            sum(e.executions_ok for e in exps),
            sum(len(e.costs) * e.n_starts for e in exps),
            sum(sum(e.held_out) for e in exps),
            sum(len(e.held_out) for e in exps),
        )


@dataclass(frozen=True)
class LearningBench:
    """The whole grid: cells in task-major order and every experiment."""

    cells: tuple[CellStats, ...]
    experiments: tuple[Experiment, ...]
    trials: int
    n_starts: int
    workers: int
    wall_s: float


def run_experiment(
    objective: SkillObjective,
    method: str,
    trials: int,
    *,
    workers: int | None = None,
    storage: str | Path | None = None,
    on_trial: Callable[[TrialRecord], None] | None = None,
    handle_signals: bool = True,
    ray: str | None = None,
) -> Experiment:
    """One learning run of ``trials`` trials; the study goes to ``storage`` (default: a
    temporary SQLite file, removed afterwards), and a study stored there before is resumed
    (its finished trials kept, only the rest run). ``ray``: run the trials on Ray
    (``"local"`` or the address of a running cluster), ``workers`` of them at once."""
    if method not in METHODS:
        raise LearningError(f"unknown method {method!r}; known: {list(METHODS)}")
    with tempfile.TemporaryDirectory(prefix="teachfit-bench-", dir=_ram_dir()) as tmp:
        study = _open_study(objective, method, trials, storage or Path(tmp) / "study.db", storage)
        t0 = time.perf_counter()
        if ray is not None:
            from teachfit.learning.ray_runner import run_study_ray

            report = run_study_ray(
                study,
                objective,
                trials,
                address=ray,
                workers=workers,
                on_trial=on_trial,
                handle_signals=handle_signals,
            )
        else:
            report = run_study(
                study,
                objective,
                trials,
                workers=workers,
                on_trial=on_trial,
                handle_signals=handle_signals,
            )
        wall = time.perf_counter() - t0
        study.close()
        if report.interrupted:  # the rest of a grid must not run on (nor count it whole)
            raise _interrupted(objective, method, study, storage)
        return Experiment.from_records(
            objective.task,
            method,
            objective.seed,
            study.trials(),
            wall,
            objective.n_starts * objective.setups,  # executions per trial
            study.n_restored,
        )


def _interrupted(
    objective: SkillObjective, method: str, study: Study, storage: str | Path | None
) -> BenchInterrupted:
    """The error of an interrupted experiment, saying where its trials are kept, if anywhere."""
    kept = (
        f"its {study.n_finished} finished trials are in {storage}: the same command resumes"
        if storage is not None
        else "its trials are discarded (keep studies to resume)"
    )
    what = f"{objective.task}/{method} seed {objective.seed}"
    return BenchInterrupted(f"{what} interrupted; {kept}")


def _open_study(
    objective: SkillObjective,
    method: str,
    trials: int,
    db: str | Path,
    storage: str | Path | None,
) -> Study:
    """The study of one experiment in ``db``, resumed when the caller keeps it (``storage``)."""
    return Study(
        db,
        task=objective.task,
        skill=objective.skill,
        space=objective.space,
        method=method,
        seed=objective.seed,
        options=method_options(method, trials),
        penalty=objective.penalty,
        resume=storage is not None,
        context=objective.context(),
        name=f"{objective.task}-{method}-{objective.seed}",
    )


def study_path(folder: str | Path, objective: SkillObjective, method: str, trials: int) -> Path:
    """Where :func:`run_learning_bench` keeps one experiment's study in ``folder``: named by
    task, method and seed, plus a digest of everything else the study is tagged with (skill,
    controller, robot, starts, task overrides, the method's options), so that other settings
    never meet a stored study of different ones and the same settings resume it."""
    tags = [objective.skill, objective.context(), method_options(method, trials)]
    digest = hashlib.sha1(json.dumps(tags, sort_keys=True).encode()).hexdigest()[:10]
    return Path(folder) / f"{objective.task}-{method}-s{objective.seed}-{digest}.db"


def _ram_dir() -> str | None:
    """A RAM-backed folder for the throw-away study database, if the system has one.

    The study commits to SQLite several times per trial; on a disk each commit waits for an
    fsync (~10 ms here, 0.1-0.3 s per 4-execution trial with the storage's own queries), on
    ``/dev/shm`` it does not. ``None``: the system's temporary folder.
    """
    shm = Path("/dev/shm")
    return str(shm) if shm.is_dir() and os.access(shm, os.W_OK) else None


def run_learning_bench(
    tasks: Sequence[str],
    methods: Sequence[str],
    experiments: int,
    trials: int,
    *,
    workers: int | None = None,
    n_starts: int = 4,
    controller: str = "adaptive",
    seed: int = 0,
    overrides: Mapping[str, float] | None = None,
    on_trial: Callable[[str, TrialRecord], None] | None = None,
    robot: str = "floating",
    ray: str | None = None,
    studies: str | Path | None = None,
    setups: int = 1,
    held_out: int = 0,
) -> LearningBench:
    """Every task x method x experiment; ``on_trial(label, record)`` reports progress;
    ``ray``: trials on Ray (see :func:`run_experiment`). ``studies``: a folder keeping each
    experiment's study (:func:`study_path`), so that an interrupted grid resumes where it
    stopped (``None``: throw-away studies). ``setups``: set-ups each trial is evaluated on;
    ``held_out``: held-out set-ups the best parameters of each experiment then run on."""
    if experiments < 1 or trials < 1:
        raise LearningError(f"experiments and trials must be >= 1, got {experiments}, {trials}")
    bad = [m for m in methods if m not in METHODS]
    if bad:
        raise LearningError(f"unknown method(s) {bad}; known: {list(METHODS)}")
    t0 = time.perf_counter()
    cells, exps = [], []
    ov = tuple(sorted((overrides or {}).items()))
    for task in tasks:
        for method in methods:
            mine = []
            for e in range(experiments):
                obj = SkillObjective(
                    task,
                    controller=controller,
                    seed=seed + e,
                    n_starts=n_starts,
                    task_overrides=ov,
                    robot=robot,
                    setups=setups,
                )
                label = f"{task}/{method} #{e + 1}"
                cb = None if on_trial is None else (lambda r, lb=label: on_trial(lb, r))
                db = None if studies is None else study_path(studies, obj, method, trials)
                exp = run_experiment(
                    obj, method, trials, workers=workers, on_trial=cb, ray=ray, storage=db
                )
                if held_out:
                    exp = replace(exp, held_out=obj.held_out(exp.best_params, held_out))
                mine.append(exp)
            cells.append(CellStats.of(mine))
            exps.extend(mine)
    n_workers = workers if workers is not None else _cores()
    return LearningBench(
        tuple(cells), tuple(exps), trials, n_starts, n_workers, time.perf_counter() - t0
    )


def _cores() -> int:
    import os

    return os.cpu_count() or 1
