"""The parts suite bench (``teachfit bench parts``): every method on every part and robot.

For each suite part (:mod:`teachfit.tasks.mesh.suite`, written as task files) and robot, four
methods, each a batch of executions with its success rate and Wilson 95 % interval:

``skill``
    the peg-in-hole skill with its default parameters on ``setups`` held-out set-ups
    (:mod:`teachfit.execution.setups`), one start each (``skill run --setups``);
``skill-learned``
    the same held-out set-ups with the parameters learned by ``learner`` over ``trials``
    trials, each evaluated on ``train_setups`` training set-ups (``bench learning --setups K
    --held-out N``);
``search``
    Ehlers et al.'s learned search (TSHIX, one blind-teacher demonstration) from ``starts``
    starts of the task's Table I protocol (``bench search --task``);
``assemble``
    the joined skill with the same search model, the taught hole 3 mm off, ``starts`` trials
    (``assemble --hole-error 3mm``).

Goal (a benchmark, not a test): every row at or above :data:`GOAL`.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from teachfit.core.errors import TeachfitError
from teachfit.metrics.stats import SuccessSummary, summarize

METHODS = ("skill", "skill-learned", "search", "assemble")
ROBOTS = ("floating", "fr3")
GOAL = 0.9
HOLE_ERROR = 0.003  # m, assemble's taught-hole error
Progress = Callable[[], None] | None


@dataclass(frozen=True)
class Sizes:
    """How many executions each method runs (the defaults are the goal's sizes) and in how many
    worker processes (``workers``: 0 in this process, ``None`` one per core)."""

    setups: int = 20  # held-out set-ups of skill and skill-learned
    trials: int = 30  # learning trials of skill-learned
    starts: int = 20  # search starts and assemble trials
    #: training set-ups per learning trial: with 4, the cheapest trial that inserted on all
    #: of them could still miss on 3 of 20 held-out ones (round8-sharp-through, floating: a
    #: tilt of 0.04 rad at full speed rode over the hole); with 8, 20/20
    train_setups: int = 8
    learner: str = "cmaes"
    points: int = 300  # TSHIX points
    workers: int | None = 0

    def __post_init__(self) -> None:
        for name in ("setups", "trials", "starts", "train_setups", "points"):
            if getattr(self, name) < 1:
                raise TeachfitError(f"--{name.replace('_', '-')} must be >= 1")

    def units(self, methods: Sequence[str]) -> int:
        """Executions (progress units) of one part on one robot."""
        per = {
            "skill": self.setups,
            "skill-learned": self.trials + self.setups,
            "search": self.starts,
            "assemble": self.starts,
        }
        return sum(per[m] for m in methods)


@dataclass(frozen=True)
class PartRow:
    """One method on one part and robot; ``failures`` each failed execution's outcome and
    reason."""

    part: str
    robot: str
    method: str
    summary: SuccessSummary
    failures: tuple[str, ...] = ()

    def commonest_failure(self) -> str:
        """The most frequent failure reason with its count (``""`` without failures)."""
        if not self.failures:
            return ""
        (why, n), *_ = Counter(self.failures).most_common(1)
        return f"{n}x {why}"


#: a batch's summary and its failures' reasons
Batch = tuple[SuccessSummary, tuple[str, ...]]


def _batch(runs: Sequence[tuple[bool, str]], times: Sequence[float] | None = None) -> Batch:
    """A batch of ``(success, reason)`` executions (times of insertion in s, NaN: none)."""
    oks = [ok for ok, _ in runs]
    summary = summarize(oks, list(times) if times is not None else [math.nan] * len(oks))
    return summary, tuple(why for ok, why in runs if not ok)


def check_choice(given: Sequence[str], known: Sequence[str], what: str) -> list[str]:
    """``given`` if every item is in ``known``, else a one-line error naming the option."""
    bad = [g for g in given if g not in known]
    if bad or not given:
        raise TeachfitError(f"--{what}: choose from {', '.join(known)} (got {', '.join(given)})")
    return list(given)


def _skill_rows(
    task: str, robot: str, sizes: Sizes, seed: int, learned: bool, progress: Progress
) -> dict[str, Batch]:
    """``skill`` (default parameters) and, with ``learned``, ``skill-learned`` on the same
    held-out set-ups."""
    from teachfit.bench.learning import run_experiment
    from teachfit.learning.objective import SkillObjective

    out = {}
    plain = SkillObjective(task, seed=seed, n_starts=1, robot=robot)
    out["skill"] = _batch(plain.held_out_runs(None, sizes.setups, progress))
    if learned:
        obj = SkillObjective(task, seed=seed, n_starts=1, robot=robot, setups=sizes.train_setups)
        tick = (lambda _r: progress()) if progress is not None else None
        exp = run_experiment(obj, sizes.learner, sizes.trials, workers=sizes.workers, on_trial=tick)
        out["skill-learned"] = _batch(obj.held_out_runs(exp.best_params, sizes.setups, progress))
    return out


def _search_rows(
    task: str, robot: str, sizes: Sizes, seed: int, methods: Sequence[str], progress: Progress
) -> dict[str, Batch]:
    """``search`` and ``assemble`` with one search model learned from the blind teacher."""
    from teachfit.bench import search as bs
    from teachfit.bench.search_jobs import run_jobs
    from teachfit.bench.search_task import task_demos, task_jobs
    from teachfit.execution.assembly import assembly_jobs, run_assembly
    from teachfit.models.search_model import SearchModel

    before = bs.ROBOT[0]
    bs.use_robot(robot)  # the teacher's and the search jobs' robot
    try:
        demos = task_demos(task, seed)
        searches = task_jobs(task, demos, seed, sizes.starts, sizes.points)
    finally:
        bs.use_robot(before)
    out = {}
    if "search" in methods:
        res = run_jobs(searches, sizes.workers, progress)
        times = [r.time_to_insertion for r in res]
        out["search"] = _batch([(r.success, r.reason) for r in res], times)
    if "assemble" in methods:
        model = SearchModel.fit(list(demos), demos[0].task)
        jobs = assembly_jobs(task, ["joined"], [HOLE_ERROR], sizes.starts, model, seed=seed,
                             robot=robot)  # fmt: skip
        trials = run_assembly(jobs, sizes.workers, progress)
        runs = [(t.success, t.reason) for t in trials]
        out["assemble"] = _batch(runs, [t.time for t in trials])
    return out


def bench_part(
    part: str,
    task: str | Path,
    robot: str,
    sizes: Sizes,
    seed: int = 0,
    methods: Sequence[str] = METHODS,
    progress: Progress = None,
) -> list[PartRow]:
    """The rows of ``methods`` on one part's task file ``task`` and ``robot``."""
    spec = str(task)
    got: dict[str, Batch] = {}
    if "skill" in methods or "skill-learned" in methods:
        got |= _skill_rows(spec, robot, sizes, seed, "skill-learned" in methods, progress)
    if "search" in methods or "assemble" in methods:
        got |= _search_rows(spec, robot, sizes, seed, methods, progress)
    return [PartRow(part, robot, m, *got[m]) for m in methods]


def run_parts(
    tasks: Mapping[str, Path],
    robots: Sequence[str],
    sizes: Sizes,
    seed: int = 0,
    methods: Sequence[str] = METHODS,
    progress: Progress = None,
    on_rows: Callable[[list[PartRow]], None] | None = None,
) -> list[PartRow]:
    """Every part (name -> task file) x robot; ``on_rows`` sees each part-robot's rows as
    they finish (to print and save them before the rest runs)."""
    out: list[PartRow] = []
    for part, path in tasks.items():
        for robot in robots:
            rows = bench_part(part, path, robot, sizes, seed, methods, progress)
            out += rows
            if on_rows is not None:
                on_rows(rows)
    return out


def goal_misses(rows: Sequence[PartRow], goal: float = GOAL) -> list[PartRow]:
    """The rows below ``goal``."""
    return [r for r in rows if r.summary.rate < goal]


def rate_cell(s: SuccessSummary) -> str:
    """``k/n = p % [low, high]`` (Wilson 95 %)."""
    return (
        f"{s.successes}/{s.trials} = {100 * s.rate:.0f} % [{100 * s.low:.0f}, {100 * s.high:.0f}]"
    )


def pivot(rows: Sequence[PartRow]) -> tuple[list[str], list[list[str]]]:
    """The rows as one line per part and robot, a column per method (``k/n [low, high]``,
    Wilson 95 %; the results page's compact table): ``(columns, lines)``."""
    methods = list(dict.fromkeys(r.method for r in rows))
    cells: dict[tuple[str, str], dict[str, str]] = {}
    for r in rows:
        s = r.summary
        mark = "" if s.rate >= GOAL else " ✗"
        cell = f"{s.successes}/{s.trials} [{100 * s.low:.0f}, {100 * s.high:.0f}]{mark}"
        cells.setdefault((r.part, r.robot), {})[r.method] = cell
    lines = [[p, rb, *(got.get(m, "") for m in methods)] for (p, rb), got in cells.items()]
    return ["part", "robot", *methods], lines
