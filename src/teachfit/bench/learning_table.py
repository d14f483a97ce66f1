"""Johannsmeier et al.'s Fig. 6 grid as text: the per-cell table and the methods' ordering per task.

Per task x method (over its experiments, seeds ``seed + e``): the mean best cost with its 95 %
t interval (s), the best parameters' success rate, how many experiments found a feasible trial
and the first one (trial number, mean over those that did), the executions of all trials that
succeeded with their Wilson 95 % interval, insertion time, robot time and wall time. The
ordering ranks a task's methods by mean best cost; ``<`` separates two neighbours whose
intervals do not overlap, ``≈`` two whose intervals overlap (not told apart by these
experiments). Experiment ``e`` of every method uses the same set-up (hole estimate, starts,
sensor noise), so the comparison is paired; the intervals shown are the unpaired ones, the
conservative reading; :func:`paired_markdown` adds the paired one: per neighbouring pair in
the ordering, the mean over common set-ups of the difference of best costs with its 95 % t
interval,

    d_e = best_{b,e} - best_{a,e},    d = mean_e d_e,    d +- t_{0.975, n-1} sd(d_e) / sqrt(n)

(``a`` the lower mean, so ``b`` is told worse when the interval's low end is above 0), and
beside each task the paper's reading of its Fig. 6 (Sec. VI; no numbers are printed there).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from teachfit.learning.curves import band
from teachfit.metrics.stats import wilson_interval

if TYPE_CHECKING:
    from teachfit.bench.learning import CellStats, LearningBench

__all__ = [
    "PAPER_ORDERING",
    "ordering",
    "ordering_markdown",
    "paired_markdown",
    "to_markdown",
    "unsolved_setups",
]

#: Johannsmeier et al.'s reading of Fig. 6 (Sec. VI), by task: "all four algorithms are suited to a
#: certain degree" for puzzle and key, BO finds worse solutions with a larger interval and stops
#: early; on the peg BO found no solution, LHS's interval is too large, PSO better, CMA-ES best.
PAPER_ORDERING = {
    "puzzle": "cmaes ≈ pso ≈ lhs < bo (BO worse on average, wider interval, stops early)",
    "key": "cmaes ≈ pso ≈ lhs < bo (BO worse on average, wider interval, stops early)",
    "peg": "cmaes < pso < lhs; bo found no solution",
}


def _f(x: float, fmt: str = ".2f") -> str:
    return "–" if math.isnan(x) else format(x, fmt)


def _ci(c: CellStats) -> str:
    if c.n < 2:
        return f"{c.best_cost_mean:.3f}"
    return f"{c.best_cost_mean:.3f} [{c.best_cost_low:.3f}, {c.best_cost_high:.3f}]"


def _executions(c: CellStats) -> str:
    if c.executions == 0:
        return "–"
    lo, hi = wilson_interval(c.executions_ok, c.executions)
    rate = 100 * c.executions_ok / c.executions
    return f"{c.executions_ok}/{c.executions} = {rate:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}]"


def _held_out(c: CellStats) -> str:
    lo, hi = wilson_interval(c.held_out_ok, c.held_out)
    rate = 100 * c.held_out_ok / max(c.held_out, 1)
    return f" {c.held_out_ok}/{c.held_out} = {rate:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}] |"


def to_markdown(bench: LearningBench) -> str:
    """The grid as a markdown table (one row per task x method), then the ordering; a column
    of the best parameters' executions on held-out set-ups where they were run."""
    held = any(c.held_out for c in bench.cells)
    head = (
        "| task | method | best cost (s) [95 % CI] | success of best | first feasible "
        "(trial) | solved | executions that succeeded [95 % Wilson] | insertion time (s) | "
        "robot time to feasible / best / all (min) | wall (s) | trials/s |"
        + (" best on held-out set-ups [95 % Wilson] |" if held else "")
        + "\n|---|---|---|---|---|---|---|---|---|---|---|"
        + ("---|" if held else "")
        + "\n"
    )
    rows = []
    for c in bench.cells:
        never = f" ({c.never_feasible} never)" if c.never_feasible else ""
        rows.append(
            f"| {c.task} | {c.method} | {_ci(c)} | "
            f"{100 * c.best_success:.0f} % | {_f(c.first_feasible_mean, '.1f')}{never} | "
            f"{c.n - c.never_feasible}/{c.n} | {_executions(c)} | "
            f"{_f(c.insertion_time, '.3f')} | {_f(c.sim_feasible_min)} / "
            f"{_f(c.sim_best_min)} / {_f(c.sim_total_min)} | {c.wall_s:.1f} | "
            f"{c.trials_per_s:.2f} |" + (_held_out(c) if held else "")
        )
    return (
        head
        + "\n".join(rows)
        + "\n\n"
        + ordering_markdown(bench.cells)
        + "\n"
        + paired_markdown(bench)
    )


def _ranked(cells: Sequence[CellStats], task: str) -> list[CellStats]:
    """``task``'s cells from the lowest mean best cost up."""
    return sorted((c for c in cells if c.task == task), key=lambda c: c.best_cost_mean)


def ordering(cells: Sequence[CellStats]) -> dict[str, str]:
    """Per task, its methods from the lowest mean best cost up, joined by ``<`` (the two
    95 % intervals do not overlap) or ``≈`` (they do)."""
    out: dict[str, str] = {}
    for task in dict.fromkeys(c.task for c in cells):
        mine = _ranked(cells, task)
        text = mine[0].method
        for a, b in zip(mine, mine[1:], strict=False):
            apart = a.n > 1 and b.n > 1 and a.best_cost_high < b.best_cost_low
            text += (" < " if apart else " ≈ ") + b.method
        out[task] = text
    return out


def ordering_markdown(cells: Sequence[CellStats]) -> str:
    """:func:`ordering` as lines ``task: a < b ≈ c ...`` with each method's interval."""
    lines = []
    for task, text in ordering(cells).items():
        mine = _ranked(cells, task)
        detail = ", ".join(f"{c.method} {_ci(c)}" for c in mine)
        lines.append(f"- ordering on {task} (mean best cost, s): **{text}** ({detail})")
    return "\n".join(lines) + "\n"


def paired_markdown(bench: LearningBench) -> str:
    """Per task: each neighbouring pair of :func:`ordering` compared on the set-ups both ran
    (``b - a`` of the best costs, mean and 95 % t interval, s), then the paper's reading."""
    best = {(e.task, e.method, e.seed): e.costs[e.best_index] for e in bench.experiments}
    lines = []
    for task in dict.fromkeys(c.task for c in bench.cells):
        mine = _ranked(bench.cells, task)
        parts = []
        for a, b in zip(mine, mine[1:], strict=False):
            seeds = sorted(
                s for (t, m, s) in best if t == task and m == a.method and (t, b.method, s) in best
            )
            diffs = [best[(task, b.method, s)] - best[(task, a.method, s)] for s in seeds]
            if len(diffs) < 2:
                parts.append(f"{b.method} - {a.method}: {len(diffs)} common set-up(s)")
                continue
            d = band([[x] for x in diffs])
            verdict = "apart" if d.low[0] > 0 else "not told apart"
            parts.append(
                f"{b.method} - {a.method} = {d.mean[0]:+.3f} [{d.low[0]:+.3f}, "
                f"{d.high[0]:+.3f}] over {len(diffs)} set-ups ({verdict})"
            )
        paper = PAPER_ORDERING.get(task, "not in the paper")
        lines.append(f"- paired on {task}: " + "; ".join(parts) + f". Paper: {paper}")
        unsolved = unsolved_setups(bench, task)
        if unsolved:
            lines.append(
                f"- set-up(s) {', '.join(map(str, unsolved))} of {task}: no method succeeded "
                "once (only failure costs there: the set-up, e.g. its taught hole estimate, "
                "is out of the skill's reach, and widens every unpaired interval)"
            )
    return "\n".join(lines) + "\n"


def unsolved_setups(bench: LearningBench, task: str) -> list[int]:
    """Seeds (set-ups) of ``task`` on which every method's experiment ran and none had a
    feasible trial (no execution succeeded)."""
    methods = {c.method for c in bench.cells if c.task == task}
    by_seed: dict[int, list[bool]] = {}
    for e in bench.experiments:
        if e.task == task:
            by_seed.setdefault(e.seed, []).append(e.first_feasible is not None)
    return sorted(
        s for s, found in by_seed.items() if len(found) == len(methods) and not any(found)
    )
