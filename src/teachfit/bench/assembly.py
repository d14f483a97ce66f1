"""Each seed alone against the three joined, on the same trials (``teachfit bench assembly``).

For a task and taught-hole errors (m), every method of
:data:`~teachfit.execution.assembly.METHODS` -- (a) Johannsmeier et al.'s skill alone, (b) Ehlers et
al.'s learned search alone from the taught pose, (c) the plan executed open loop, (d) the joined
pipeline -- runs the same ``trials`` trials (taught hole, start, seeds from
:func:`~teachfit.execution.batch.episode_seed`). The search model is learned from the seeded
blind teacher's demonstrations, as in Ehlers et al.'s benchmarks: one worst-case demonstration on
``peg2d`` and on other x-y tasks, two from opposite ends on ``socket3d`` and other x-y-rz tasks.
Rows give success (Wilson 95 % interval) and the median time to insertion (s from the start,
the approach included). With ``learned`` parameters (e.g. ``teachfit learn skill --skill
peg-in-hole+search:MODEL``) a fifth row, ``"joined-learned"``, runs the joined graph with them
on the same trials.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from teachfit.bench.search import ROBOT, _peg_demo, _socket_demos
from teachfit.core.errors import TeachfitError
from teachfit.execution.assembly import (
    JOINED_LEARNED,
    METHODS,
    AssemblyTrial,
    assembly_jobs,
    method_skill,
    run_assembly,
)
from teachfit.execution.teacher import BlindTeacher
from teachfit.metrics.stats import SuccessSummary, summarize
from teachfit.models.search_model import SearchModel
from teachfit.skills.params import read_params_toml
from teachfit.tasks.registry import get_task

Rows = dict[str, list[tuple[float, SuccessSummary]]]
#: the planned-path cells (``bench_plan_task``); every other task is peg-type (``bench_task``)
PLAN_CELLS = ("l-groove", "tenon")


def task_model(name: str, seed: int = 0) -> SearchModel:
    """The search model the benchmark learns for task ``name`` from the seeded teacher."""
    task = get_task(name)
    if name == "peg2d":
        return _peg_demo(seed, float(task.params.clearance), ROBOT[0])[1]
    if name == "socket3d":
        return SearchModel.fit(_socket_demos(task, seed), name)
    n = 2 if task.has_rz else 1
    demos, _ = BlindTeacher(task, seed=seed, robot=ROBOT[0]).record(n)
    return SearchModel.fit(demos, name, covariance="diag" if n > 1 else "full")


def bench_inputs(
    names: Sequence[str], search: str | Path | None, params: str | Path | None, seed: int = 0
) -> tuple[SearchModel | None, dict[str, float]]:
    """The search model file ``search`` (default: :func:`task_model`) and the joined skill's
    ``params`` (TOML, e.g. from ``learn skill``) for ``bench assembly``; both need exactly one
    peg-type task in ``names`` and are checked before any trial runs."""
    if search is None and params is None:
        return None, {}
    pegs = [n for n in names if n not in PLAN_CELLS]
    if len(pegs) != 1:
        raise TeachfitError("--search/--params: give exactly one peg-type task in --tasks")
    model = SearchModel.load(search, task=pegs[0]) if search else task_model(pegs[0], seed)
    if params is None:
        return model, {}
    sk = method_skill(JOINED_LEARNED, model, "peg-in-hole", "adaptive")
    return model, read_params_toml(params, sk.params, sk.users())


def summarise(
    trials: Sequence[AssemblyTrial], methods: Sequence[str], errors: Sequence[float]
) -> Rows:
    """``rows[method] = [(error, summary), ...]`` from the trials of one task."""
    rows: Rows = {}
    for m in methods:
        rows[m] = []
        for e in errors:
            sel = [t for t in trials if t.method == m and t.hole_error == e]
            rows[m].append((e, summarize([t.success for t in sel], [t.time for t in sel])))
    return rows


def bench_task(
    name: str,
    errors: Sequence[float],
    trials: int,
    seed: int = 0,
    workers: int | None = None,
    progress: Callable[[], None] | None = None,
    methods: Sequence[str] = METHODS,
    model: SearchModel | None = None,
    learned: Mapping[str, float] | None = None,
) -> Rows:
    """Run every method at every taught-hole error on task ``name`` (and ``"joined-learned"``
    with ``learned`` parameters, when given); see the module docstring."""
    if not errors:
        raise TeachfitError("give at least one taught-hole error")
    model = model if model is not None else task_model(name, seed)
    jobs = assembly_jobs(name, methods, errors, trials, model, seed=seed, robot=ROBOT[0])
    if learned:
        values = tuple(sorted((k, float(v)) for k, v in learned.items()))
        jobs += assembly_jobs(
            name, [JOINED_LEARNED], errors, trials, model, seed=seed, robot=ROBOT[0], learned=values
        )
        methods = (*methods, JOINED_LEARNED)
    return summarise(run_assembly(jobs, workers, progress), methods, errors)


def bench_plan_task(
    part: str,
    trials: int,
    seed: int = 0,
    progress: Callable[[], None] | None = None,
    max_error: float = 0.003,
) -> tuple[Rows, dict[str, int]]:
    """(c) the plan open loop vs (d) joined (compliant tracking + seating skill) on the
    L-groove or tenon cell, on the robot of :func:`~teachfit.bench.search.use_robot`, the
    same capture errors (0.5 mm-``max_error``, 0.5-2 deg) for both; rows keyed by
    ``max_error`` count the simulator's ground truth (the open loop has no success test of its
    own) with the execution's end time (s); also the *measured* successes per method (the
    joined skill's own verdict)."""
    from teachfit.execution.plan_contact import plan_path, run_plan_trials, timed_path

    plan = plan_path(part, seed=seed)
    if not plan.success:
        raise TeachfitError(f"no plan for {part}: {plan.message}")
    path = timed_path(part, plan)
    rows: Rows = {}
    measured: dict[str, int] = {}
    for method in ("open-loop", "joined"):
        out = run_plan_trials(
            part, path, trials, seed, method, lambda _t: progress() if progress else None,
            robot_name=ROBOT[0], translation=(0.0005, max_error),
        )  # fmt: skip
        truth = [bool(t.ground_truth) for t in out]
        rows[method] = [(max_error, summarize(truth, [t.result.t_end for t in out]))]
        measured[method] = sum(t.success for t in out)
    return rows, measured


def losses(rows: Rows, joined: str = "joined") -> list[str]:
    """Where ``joined`` does not beat a single method: a lower success rate, or the same rate
    with a longer median time (one line each)."""
    out = []
    for m, pts in rows.items():
        if m == joined:
            continue
        for (e, s), (_, j) in zip(pts, rows[joined], strict=True):
            worse_rate = j.rate < s.rate
            slower = j.rate == s.rate and not (j.median_time <= s.median_time)
            if worse_rate or (slower and np.isfinite(s.median_time)):
                why = "success" if worse_rate else "time"
                out.append(f"{m} at {e * 1e3:g} mm on {why}: joined {j}; {m} {s}")
    return out
