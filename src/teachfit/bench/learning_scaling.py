"""Johannsmeier et al.'s learning runner, measured: the speed-up from workers and the trials/s per
count.

:func:`speedup` times one study with 1 and with N workers (alternating runs, fastest kept);
:func:`scaling` measures trials/s for several worker counts in one run (local pools or Ray).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from teachfit.bench.learning import run_experiment
from teachfit.core.params import LearningError
from teachfit.learning.objective import SkillObjective

__all__ = ["ScalingRow", "scaling", "scaling_markdown", "speedup"]


def speedup(
    task: str = "puzzle",
    method: str = "cmaes",
    trials: int = 24,
    workers: int = 2,
    n_starts: int = 4,
    seed: int = 0,
    repeats: int = 2,
) -> tuple[float, float, float]:
    """Wall time (s) of the same study with 1 and with ``workers`` workers, and the ratio.

    The runs alternate (1, N, 1, N, ...) ``repeats`` times and each count keeps its fastest
    run: on a machine shared with other work the minimum is the least disturbed estimate.
    """
    obj = SkillObjective(task, seed=seed, n_starts=n_starts)
    t1 = tn = math.inf
    for _ in range(max(1, repeats)):
        t1 = min(t1, run_experiment(obj, method, trials, workers=1).wall_s)
        tn = min(tn, run_experiment(obj, method, trials, workers=workers).wall_s)
    return t1, tn, t1 / tn


@dataclass(frozen=True)
class ScalingRow:
    """One worker count of :func:`scaling`: ``trials`` trials in ``wall_s`` seconds."""

    workers: int
    trials: int
    wall_s: float

    @property
    def trials_per_s(self) -> float:
        return self.trials / self.wall_s if self.wall_s > 0 else math.nan


def scaling(
    workers: Sequence[int] = (1, 2, 4),
    *,
    task: str = "puzzle",
    trials_per_worker: int = 6,
    n_starts: int = 1,
    seed: int = 0,
    ray: str | None = None,
) -> list[ScalingRow]:
    """Trials/s of a learning study with each worker count, measured in one run.

    Each count runs ``trials_per_worker * workers`` trials of a Latin hypercube study (no
    generation barrier: this measures the runner, not a learner's parallelism). With ``ray``
    the counts share one Ray connection, and a warm-up study on ``max(workers)`` workers
    first starts the Ray workers and builds their MuJoCo scenes, so the figures are trials
    alone. Without it each count starts a fresh local process pool (start-up included).
    """
    counts = sorted({int(w) for w in workers})
    if not counts or counts[0] < 1 or trials_per_worker < 1:
        raise LearningError(f"need worker counts >= 1 and trials >= 1, got {workers}")
    obj = SkillObjective(task, seed=seed, n_starts=n_starts)
    started, reaper = False, None
    if ray is not None:
        from teachfit.learning.ray_runner import _init, import_ray

        started, reaper = _init(import_ray(), ray, counts[-1])
    try:
        if ray is not None:
            run_experiment(obj, "lhs", counts[-1], workers=counts[-1], ray=ray)  # warm-up
        rows = []
        for w in counts:
            n = trials_per_worker * w
            exp = run_experiment(obj, "lhs", n, workers=w, ray=ray)
            rows.append(ScalingRow(w, len(exp.costs), exp.wall_s))
        return rows
    finally:
        if started:
            import_ray().shutdown()
        if reaper is not None:
            reaper.stop()  # what the shutdown left of a local instance is killed


def scaling_markdown(rows: Sequence[ScalingRow]) -> str:
    """The scaling as a markdown table: speed-up over the fewest workers, and per worker."""
    base = rows[0]
    head = (
        "| workers | trials | wall (s) | trials/s | speed-up | per worker (x linear) |\n"
        "|---|---|---|---|---|---|\n"
    )
    lines = []
    for r in rows:
        up = r.trials_per_s / base.trials_per_s
        per = up * base.workers / r.workers
        lines.append(
            f"| {r.workers} | {r.trials} | {r.wall_s:.1f} | {r.trials_per_s:.2f} | "
            f"x{up:.2f} | {per:.2f} |"
        )
    return head + "\n".join(lines) + "\n"
