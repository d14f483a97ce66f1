"""Table I of Wang et al. 2019 (docs/methods.md), reproduced over many seeds per task.

For each task and seed: a synthetic demonstration (seeded), then the demonstration-guided
planner (seeded, OMPL included); beside it the same planner without demonstration, with a
generous budget, on the first seeds. Reported: candidate key poses available and used,
planning time (median, p90), success rate, the paper's numbers, the speed-up of guided over
unguided planning, and the cost of one collision check, against a quaternion-to-matrix
conversion by scipy timed in the same run. ``teachfit bench planning`` only parses its options,
calls :func:`run_planning_bench` and prints :func:`report_table` and :func:`report_notes`.
"""

from __future__ import annotations

import datetime as _dt
import platform
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teachfit.core.atomic import atomic_append_text
from teachfit.core.errors import PlanningError
from teachfit.core.geometry import Pose, wxyz_to_rotation
from teachfit.plans.collision import CollisionChecker
from teachfit.plans.plan_types import PlanResult
from teachfit.plans.planner import PLANNERS, MotionPlanner, PlannerConfig
from teachfit.plans.synth import synth_demo
from teachfit.tasks.parts import PARTS, Assembly
from teachfit.tasks.registry import build_assembly

__all__ = [
    "TABLE_COLUMNS",
    "CheckCost",
    "ModeStats",
    "PlanningBenchConfig",
    "TaskBench",
    "append_markdown",
    "collision_check_cost",
    "report_notes",
    "report_table",
    "run_planning_bench",
    "to_markdown",
]


@dataclass(frozen=True)
class PlanningBenchConfig:
    """What :func:`run_planning_bench` runs.

    Attributes
    ----------
    tasks : tuple of str
        Task names (keys of :data:`teachfit.tasks.parts.PARTS`).
    seeds : int
        Seeds per task for the guided planner (seeds 0 .. seeds-1).
    te : float
        Budget per attempt (s) of the guided planner.
    max_checks : int or None
        Budget per attempt of the guided planner in collision checks instead of ``te``: its
        success rates and key poses used are then the same on every machine.
    planner : str
        OMPL planner name.
    no_demo_seeds : int
        How many of the same seeds the unguided planner runs (0 skips it).
    no_demo_budget : float
        Budget (s) of each unguided run.
    overrides : tuple of (name, value)
        Dimension overrides (m) applied to every task (``build_assembly``).
    """

    tasks: tuple[str, ...] = ("l-groove", "tenon")
    seeds: int = 50
    te: float = 0.002
    max_checks: int | None = None
    planner: str = "RRTConnect"
    no_demo_seeds: int = 5
    no_demo_budget: float = 30.0
    overrides: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        if self.seeds < 1:
            raise PlanningError(f"seeds must be >= 1, got {self.seeds}")
        unknown = [t for t in self.tasks if t not in PARTS]
        if unknown or not self.tasks:
            raise PlanningError(f"unknown or no task(s) {unknown}; known: {', '.join(PARTS)}")
        if self.planner not in PLANNERS:
            raise PlanningError(f"unknown planner {self.planner!r}; known: {', '.join(PLANNERS)}")
        if self.no_demo_seeds < 0 or not self.no_demo_budget > 0 or not self.te > 0:
            raise PlanningError("no_demo_seeds must be >= 0, te and no_demo_budget > 0")
        if self.max_checks is not None and self.max_checks < 1:
            raise PlanningError(f"max_checks must be >= 1, got {self.max_checks}")

    @property
    def n_no_demo(self) -> int:
        """Unguided runs per task."""
        return min(self.no_demo_seeds, self.seeds)

    @property
    def n_runs(self) -> int:
        """Planning queries in all (for a progress bar)."""
        return len(self.tasks) * (self.seeds + self.n_no_demo)

    def check_overrides(self) -> None:
        """Build each task's parts with :attr:`overrides` once: an override a task does not
        have raises its PlanningError before any run."""
        for task in self.tasks:
            build_assembly(task, **dict(self.overrides))

    def command(self) -> str:
        """The ``teachfit bench planning`` command line that runs this configuration."""
        checks = "" if self.max_checks is None else f" --max-checks {self.max_checks}"
        checks += "".join(f" --task-param {k}={v:g}" for k, v in self.overrides)
        return (
            f"teachfit bench planning --tasks {','.join(self.tasks)} --runs {self.seeds} "
            f"--te {self.te:g}{checks} --planner {self.planner} --no-demo-runs "
            f"{self.no_demo_seeds} --no-demo-budget {self.no_demo_budget:g}"
        )


@dataclass(frozen=True)
class CheckCost:
    """Wall time (us) of one collision check of a task, and of the same-run baseline.

    ``contact_us``: at the goal pose (the parts a clearance apart: coal's narrow phase works
    hardest); ``free_us``: at the start pose. ``baseline_us``: one quaternion-to-matrix
    conversion by scipy (``wxyz_to_rotation(q).as_matrix()``), timed in the same run, so
    that the ratios compare across machines. Each figure is the fastest of ``repeats`` loops
    of ``n`` calls.
    """

    contact_us: float
    free_us: float
    baseline_us: float
    n: int


@dataclass(frozen=True)
class ModeStats:
    """Statistics of one planner mode on one task.

    Times are in s. ``used`` counts key poses in the successful attempts (0 without demo).
    Failed runs count with their full time in the time statistics. ``budget_s`` is the budget
    per attempt in ``budget_unit``: ``"s"``, or ``"checks"`` (collision checks).
    """

    mode: str
    n: int
    budget_s: float
    success_rate: float
    time_median: float
    time_p90: float
    total_median: float
    used_min: int
    used_max: int
    used_median: float
    candidates: int
    budget_unit: str = "s"

    @staticmethod
    def from_results(
        mode: str, budget: float, results: Sequence[PlanResult], unit: str = "s"
    ) -> ModeStats:
        """Aggregate :class:`~teachfit.plans.planner.PlanResult` objects."""
        if not results:
            raise PlanningError(f"no runs to aggregate for mode {mode!r}")
        times = np.array([r.time_s for r in results])
        totals = np.array([r.total_s for r in results])
        ok = [r for r in results if r.success]
        used = np.array([r.used_key_poses for r in ok]) if ok else np.zeros(1, dtype=int)
        return ModeStats(
            mode=mode,
            n=len(results),
            budget_s=budget,
            success_rate=len(ok) / len(results),
            time_median=float(np.median(times)),
            time_p90=float(np.percentile(times, 90)),
            total_median=float(np.median(totals)),
            used_min=int(used.min()),
            used_max=int(used.max()),
            used_median=float(np.median(used)),
            candidates=int(results[0].candidates),
            budget_unit=unit,
        )


@dataclass(frozen=True)
class TaskBench:
    """Guided and unguided statistics of one task, with the paper's numbers.

    ``speedup`` is the unguided median time over the guided one on the unguided seeds; when
    some unguided runs failed, their budget stands in for their time, so it is a lower bound
    (``speedup_is_bound``).
    """

    task: str
    demo: ModeStats
    no_demo: ModeStats | None
    speedup: float | None
    speedup_is_bound: bool
    paper_candidates: int
    paper_used: tuple[int, int]
    paper_time: tuple[float, float]
    check: CheckCost


def _per_call_us(fn: Callable[[], object], n: int, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        best = min(best, time.perf_counter() - t0)
    return 1e6 * best / n


def collision_check_cost(asm: Assembly, n: int = 2000, repeats: int = 3) -> CheckCost:
    """Time the planner's collision check (``collides_xyzq``) at the goal and the start."""
    if n < 1 or repeats < 1:
        raise PlanningError(f"n and repeats must be >= 1, got {n}, {repeats}")
    checker = CollisionChecker.of(asm)
    goal_pose = Pose.from_matrix(asm.goal)
    goal, start = (
        tuple(float(v) for v in p.as_array()) for p in (goal_pose, Pose.from_matrix(asm.start))
    )
    quat = goal_pose.quat
    return CheckCost(
        contact_us=_per_call_us(lambda: checker.collides_xyzq(*goal), n, repeats),
        free_us=_per_call_us(lambda: checker.collides_xyzq(*start), n, repeats),
        baseline_us=_per_call_us(lambda: wxyz_to_rotation(quat).as_matrix(), n, repeats),
        n=n,
    )


def _task_bench(
    task: str, cfg: PlanningBenchConfig, progress: Callable[[str, int], None] | None
) -> TaskBench:
    asm = build_assembly(task, **dict(cfg.overrides))
    mp = MotionPlanner(
        asm, PlannerConfig(planner=cfg.planner, te=cfg.te, max_checks=cfg.max_checks)
    )
    guided = []
    for seed in range(cfg.seeds):
        guided.append(mp.plan(synth_demo(asm, seed), seed=seed))
        if progress:
            progress(f"{task} demo", seed + 1)
    # the unguided planner's budget is always time: its median is the speed-up's numerator
    unguided = mp if cfg.max_checks is None else MotionPlanner(asm, PlannerConfig(cfg.planner))
    plain = []
    for seed in range(cfg.n_no_demo):
        plain.append(unguided.plan(None, te=cfg.no_demo_budget, seed=seed))
        if progress:
            progress(f"{task} no-demo", seed + 1)
    speedup = None
    if plain:
        t_plain = np.median([r.time_s for r in plain])
        t_guided = np.median([r.time_s for r in guided[: len(plain)]])
        speedup = float(t_plain / max(t_guided, 1e-9))
    budget, unit = (cfg.te, "s") if cfg.max_checks is None else (float(cfg.max_checks), "checks")
    return TaskBench(
        task=task,
        demo=ModeStats.from_results("demo", budget, guided, unit),
        no_demo=ModeStats.from_results("no-demo", cfg.no_demo_budget, plain) if plain else None,
        speedup=speedup,
        speedup_is_bound=bool(plain) and not all(r.success for r in plain),
        paper_candidates=asm.paper.candidates,
        paper_used=asm.paper.used,
        paper_time=asm.paper.time_s,
        check=collision_check_cost(asm),
    )


def run_planning_bench(
    cfg: PlanningBenchConfig, progress: Callable[[str, int], None] | None = None
) -> list[TaskBench]:
    """Run the Table I protocol; ``progress`` is called with ``(label, runs_done)`` per run."""
    return [_task_bench(task, cfg, progress) for task in cfg.tasks]


TABLE_COLUMNS = (
    "task",
    "planner",
    "runs",
    "demo poses available",
    "used",
    "median time (s)",
    "p90 time (s)",
    "median incl. smoothing+verify (s)",
    "success",
)


def _row(task: str, s: ModeStats) -> list[str]:
    guided = s.mode == "demo"
    budget = f"budget {s.budget_s:g} {s.budget_unit}" + ("/attempt" if guided else "")
    return [
        task,
        s.mode,
        str(s.n),
        str(s.candidates) if guided else "-",
        f"{s.used_min}-{s.used_max} (med {s.used_median:g})" if guided else "-",
        f"{s.time_median:.3f}",
        f"{s.time_p90:.3f}",
        f"{s.total_median:.3f}",
        f"{100 * s.success_rate:.0f} % ({budget})",
    ]


def report_table(results: Sequence[TaskBench]) -> list[list[str]]:
    """Rows of the results table (columns :data:`TABLE_COLUMNS`), the paper's row per task."""
    rows = []
    for r in results:
        rows.append(_row(r.task, r.demo))
        if r.no_demo is not None:
            rows.append(_row(r.task, r.no_demo))
        rows.append(
            [
                r.task,
                "paper (DDRRT-Connect, i5-8250U)",
                "5",
                str(r.paper_candidates),
                f"{r.paper_used[0]}-{r.paper_used[1]}",
                f"{r.paper_time[0]}-{r.paper_time[1]} (range)",
                "-",
                "-",
                "5/5 within t_e = 5 s",
            ]
        )
    return rows


def report_notes(results: Sequence[TaskBench]) -> list[str]:
    """One line per speed-up of guided over unguided planning and per collision-check cost."""
    lines = []
    for r in results:
        if r.speedup is not None and r.no_demo is not None:
            sign = ">= " if r.speedup_is_bound else ""
            lines.append(
                f"{r.task}: speed-up with demonstration {sign}{r.speedup:.0f}x (median over "
                f"{r.no_demo.n} seeds, no-demo budget {r.no_demo.budget_s:g} s)"
            )
    for r in results:
        c = r.check
        lines.append(
            f"{r.task}: collision check {c.contact_us:.1f} us per call at the goal (near contact), "
            f"{c.free_us:.1f} us at the start = {c.contact_us / c.baseline_us:.2f}x and "
            f"{c.free_us / c.baseline_us:.2f}x one scipy quaternion-to-matrix conversion "
            f"({c.baseline_us:.1f} us, same run; fastest of 3 x {c.n} calls)"
        )
    return lines


def to_markdown(results: Sequence[TaskBench], *, command: str = "") -> str:
    """A markdown section with the table, the paper's numbers, speed-ups and check costs."""
    lines = [
        f"## Planning with demonstrated key poses (Table I), {_dt.date.today().isoformat()}",
        "",
        f"Machine: {platform.machine()} {platform.processor() or ''}".rstrip()
        + (f"; command: `{command}`" if command else ""),
        "",
        "| " + " | ".join(TABLE_COLUMNS) + " |",
        "|" + "---|" * len(TABLE_COLUMNS),
    ]
    lines += ["| " + " | ".join(row) + " |" for row in report_table(results)]
    lines += [""] + [f"- {line}" for line in report_notes(results)] + [""]
    return "\n".join(lines)


def append_markdown(text: str, path: str | Path = "BENCHMARKS.md") -> Path:
    """Append ``text`` to ``path`` (created with a title when missing)."""
    path = Path(path)
    head = "" if path.exists() else "# Benchmarks\n\n"
    return atomic_append_text(path, head + text + "\n", "benchmark file")
