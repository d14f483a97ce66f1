"""Table I of the planning paper (METHODS.md C), reproduced over many seeds per task.

For each task and seed: a synthetic demonstration (seeded), then the demonstration-guided
planner; beside it the same planner without demonstration, with a generous budget, on the
first seeds. Reported: candidate key poses available and used, planning time (median, p90),
success rate, the paper's numbers, and the speed-up of guided over unguided planning.
"""

from __future__ import annotations

import datetime as _dt
import platform
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teachfit.core.errors import PlanningError
from teachfit.plans.parts import PARTS, build_assembly
from teachfit.plans.planner import MotionPlanner, PlannerConfig
from teachfit.plans.synth import synth_demo

__all__ = ["ModeStats", "TaskBench", "append_markdown", "run_planning_bench", "to_markdown"]


@dataclass(frozen=True)
class ModeStats:
    """Statistics of one planner mode on one task.

    Times are in s. ``used`` counts key poses in the successful attempts (0 without demo).
    Failed runs count with their full time in the time statistics.
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

    @staticmethod
    def from_results(mode: str, budget: float, results: Sequence[object]) -> ModeStats:
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


def run_planning_bench(
    tasks: Sequence[str],
    seeds: int,
    *,
    te: float = 0.01,
    planner: str = "RRTConnect",
    no_demo_seeds: int = 5,
    no_demo_budget: float = 30.0,
    progress: Callable[[str, int], None] | None = None,
) -> list[TaskBench]:
    """Run the Table I protocol.

    Parameters
    ----------
    tasks : sequence of str
        Task names (keys of :data:`teachfit.plans.parts.PARTS`).
    seeds : int
        Seeds per task for the guided planner (seeds 0 .. seeds-1).
    te : float
        Budget per attempt (s) of the guided planner.
    planner : str
        OMPL planner name.
    no_demo_seeds : int
        How many of the same seeds the unguided planner runs (0 skips it).
    no_demo_budget : float
        Budget (s) of each unguided run.
    progress : callable, optional
        Called with ``(label, runs_done)`` after each run.
    """
    if seeds < 1:
        raise PlanningError(f"seeds must be >= 1, got {seeds}")
    unknown = [t for t in tasks if t not in PARTS]
    if unknown or not tasks:
        raise PlanningError(f"unknown or no task(s) {unknown}; known: {', '.join(PARTS)}")
    out = []
    for task in tasks:
        asm = build_assembly(task)
        mp = MotionPlanner(asm, PlannerConfig(planner=planner, te=te))
        guided = []
        for seed in range(seeds):
            guided.append(mp.plan(synth_demo(asm, seed), seed=seed))
            if progress:
                progress(f"{task} demo", seed + 1)
        demo_stats = ModeStats.from_results("demo", te, guided)
        plain_stats, speedup, bound = None, None, False
        n_plain = min(no_demo_seeds, seeds)
        if n_plain > 0:
            plain = []
            for seed in range(n_plain):
                plain.append(mp.plan(None, te=no_demo_budget, seed=seed))
                if progress:
                    progress(f"{task} no-demo", seed + 1)
            plain_stats = ModeStats.from_results("no-demo", no_demo_budget, plain)
            t_plain = np.median([r.time_s for r in plain])
            t_guided = np.median([r.time_s for r in guided[:n_plain]])
            speedup = float(t_plain / max(t_guided, 1e-9))
            bound = not all(r.success for r in plain)
        out.append(
            TaskBench(
                task=task,
                demo=demo_stats,
                no_demo=plain_stats,
                speedup=speedup,
                speedup_is_bound=bound,
                paper_candidates=asm.paper.candidates,
                paper_used=asm.paper.used,
                paper_time=asm.paper.time_s,
            )
        )
    return out


def _row(task: str, s: ModeStats) -> str:
    used = "-" if s.mode == "no-demo" else f"{s.used_min}-{s.used_max} (med {s.used_median:g})"
    cand = "-" if s.mode == "no-demo" else str(s.candidates)
    return (
        f"| {task} | {s.mode} | {s.n} | {cand} | {used} | {s.time_median:.3f} | "
        f"{s.time_p90:.3f} | {s.total_median:.3f} | {100 * s.success_rate:.0f} % "
        f"(budget {s.budget_s:g} s{'/attempt' if s.mode == 'demo' else ''}) |"
    )


def to_markdown(results: Sequence[TaskBench], *, command: str = "") -> str:
    """A markdown section with the table, the paper's numbers and the speed-ups."""
    lines = [
        f"## Planning with demonstrated key poses (Table I), {_dt.date.today().isoformat()}",
        "",
        f"Machine: {platform.machine()} {platform.processor() or ''}".rstrip()
        + (f"; command: `{command}`" if command else ""),
        "",
        "| task | planner | runs | demo poses available | used | median time (s) | "
        "p90 time (s) | median incl. smoothing+verify (s) | success |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        lines.append(_row(r.task, r.demo))
        if r.no_demo is not None:
            lines.append(_row(r.task, r.no_demo))
        lines.append(
            f"| {r.task} | paper (DDRRT-Connect, i5-8250U) | 5 | {r.paper_candidates} | "
            f"{r.paper_used[0]}-{r.paper_used[1]} | {r.paper_time[0]}-{r.paper_time[1]} "
            "(range) | - | - | 5/5 within t_e = 5 s |"
        )
    lines.append("")
    for r in results:
        if r.speedup is not None:
            sign = ">= " if r.speedup_is_bound else ""
            lines.append(f"- {r.task}: speed-up with demonstration {sign}{r.speedup:.0f}x")
    lines.append("")
    return "\n".join(lines)


def append_markdown(text: str, path: str | Path = "BENCHMARKS.md") -> Path:
    """Append ``text`` to ``path`` (created with a title when missing)."""
    path = Path(path)
    head = "" if path.exists() else "# Benchmarks\n\n"
    with path.open("a", encoding="utf-8") as fh:
        fh.write(head + text + "\n")
    return path
