"""How hard a skill task is for learning: the success of random parameters, and throughput.

Johannsmeier et al. 2019 uses Latin hypercube sampling as "an uninformed sampler to gain insights
into the difficulty of the problems at hand" (Sec. IV). :func:`random_rate` measures exactly that:
per task, ``experiments`` set-ups (seeds ``seed + e``: hole estimate, starts, sensor noise), each
evaluating ``trials`` parameter sets of a Latin hypercube design (every learned parameter
uniform in its domain, the log ones in log scale) from the ``n_starts`` starts. It reports
the fraction of executions that succeeded with its Wilson 95 % interval, the fraction of
feasible trials (any start succeeded) and the throughput in executions per CPU-second (this
process and its workers together, ``resource.getrusage``), from which :func:`grid_projection`
projects the wall time of Johannsmeier et al.'s whole Fig. 6 grid. A learning benchmark
discriminates between methods only if random parameters mostly fail (the issue asks for <= 40 %).
"""

from __future__ import annotations

import math
import resource
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from teachfit.bench.learning import run_experiment
from teachfit.core.params import LearningError
from teachfit.learning.objective import SkillObjective
from teachfit.learning.study import TrialRecord
from teachfit.metrics.stats import wilson_interval

__all__ = [
    "GRID",
    "RandomRate",
    "cpu_seconds",
    "grid_projection",
    "random_rate",
    "random_rate_markdown",
]

#: the issue's full Fig. 6 grid: tasks x methods x experiments x trials x starts
GRID = (3, 4, 5, 130, 4)


@dataclass(frozen=True)
class RandomRate:
    """Random parameters on one task: counts, Wilson 95 % bounds and CPU / wall seconds."""

    task: str
    successes: int
    executions: int
    feasible: int
    trials: int
    low: float
    high: float
    cpu_s: float
    wall_s: float

    @property
    def rate(self) -> float:
        return self.successes / self.executions

    @property
    def executions_per_cpu_s(self) -> float:
        return self.executions / self.cpu_s if self.cpu_s > 0 else math.nan


def cpu_seconds() -> float:
    """CPU seconds (user + system) of this process and its finished children."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def random_rate(
    task: str,
    trials: int = 20,
    experiments: int = 2,
    *,
    n_starts: int = 4,
    seed: int = 0,
    overrides: Mapping[str, float] | None = None,
    workers: int | None = None,
    on_trial: Callable[[TrialRecord], None] | None = None,
) -> RandomRate:
    """Success of ``trials`` Latin hypercube parameter sets on each of ``experiments``
    set-ups of ``task`` (see the module docstring); ``workers`` as for a learning study."""
    if trials < 1 or experiments < 1:
        raise LearningError(f"trials and experiments must be >= 1, got {trials}, {experiments}")
    ov = tuple(sorted((overrides or {}).items()))
    ok = execs = feasible = n = 0
    cpu0, wall0 = cpu_seconds(), time.perf_counter()
    for e in range(experiments):
        obj = SkillObjective(task, seed=seed + e, n_starts=n_starts, task_overrides=ov)
        exp = run_experiment(obj, "lhs", trials, workers=workers, on_trial=on_trial)
        for rate, good in zip(exp.success_rate, exp.feasible, strict=True):
            ok += round(rate * n_starts)
            feasible += bool(good)
        execs += len(exp.costs) * n_starts
        n += len(exp.costs)
    lo, hi = wilson_interval(ok, execs)
    return RandomRate(
        task, ok, execs, feasible, n, lo, hi, cpu_seconds() - cpu0, time.perf_counter() - wall0
    )


def grid_projection(rates: Sequence[RandomRate], workers: int = 2) -> tuple[float, float]:
    """Executions per CPU-second over ``rates`` and the projected wall time (s) of the
    :data:`GRID` on ``workers`` cores, at that throughput (learners' own time excluded)."""
    execs = sum(r.executions for r in rates)
    cpu = sum(r.cpu_s for r in rates)
    per_cpu_s = execs / cpu if cpu > 0 else math.nan
    total = math.prod(GRID[:3]) * GRID[3] * GRID[4]
    return per_cpu_s, total / (per_cpu_s * workers)


def random_rate_markdown(rates: Sequence[RandomRate], workers: int = 2) -> str:
    """The measurement as a markdown table plus the grid projection line."""
    head = (
        "| task | executions | success [95 % Wilson] | feasible trials | executions/CPU-s |\n"
        "|---|---|---|---|---|\n"
    )
    rows = [
        f"| {r.task} | {r.executions} | {r.successes}/{r.executions} = {100 * r.rate:.0f} % "
        f"[{100 * r.low:.0f}, {100 * r.high:.0f}] | {r.feasible}/{r.trials} | "
        f"{r.executions_per_cpu_s:.2f} |"
        for r in rates
    ]
    per, wall = grid_projection(rates, workers)
    t, m, e, n, s = GRID
    tail = (
        f"\nthroughput {per:.2f} executions/CPU-s: the {t}x{m}x{e}x{n}x{s} grid "
        f"({t * m * e * n * s} executions) projects to {wall / 60:.0f} min on {workers} "
        "cores (learners' own time excluded)\n"
    )
    return head + "\n".join(rows) + "\n" + tail
