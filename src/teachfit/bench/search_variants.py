"""Ehlers et al.'s Table I / Table III protocols on a seeded sample of task variants.

Each variant (:mod:`teachfit.tasks.variants`) is run as a user would run it, nothing tuned per
variant: the blind teacher records on that variant (one demonstration for ``peg2d``; two from
opposite ends of the socket for ``socket3d``, as Table III), the model is ``learn search``'s
default fit (:meth:`SearchModel.fit` without options), then TSHIX (a new trajectory per start,
300 / 600 points; with ``passes`` > 1 a tour that ends without the hole goes on through fresh
samples, as the joined skill's search does until its time limit) and one ergodic trajectory of
about the mean TSHIX length, on the protocol's starts. A variant whose teacher recorded nothing
gets no rows but its discard reasons.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from teachfit.bench.search import Progress, Row, _jobs, _row, record_socket_demos
from teachfit.bench.search_jobs import run_jobs
from teachfit.core.errors import TeachfitError
from teachfit.demonstrations.dataset import Demonstration
from teachfit.execution.batch import episode_seed
from teachfit.execution.teacher import BlindTeacher
from teachfit.models.search_model import SearchModel
from teachfit.tasks.variants import Variant, sample_variants

if TYPE_CHECKING:
    from teachfit.viz.variant_figures import VariantRecord

#: the protocol of each task: (protocol name, TSHIX points, demonstrations)
PROTOCOLS = {"peg2d": ("table1", 300, 1), "socket3d": ("table3", 600, 2)}
#: Ehlers et al.'s goal per task: TSHIX success on every variant at least this
GOALS = {"peg2d": 0.90, "socket3d": 0.85}


@dataclass(frozen=True)
class VariantResult:
    """One variant's outcome: demonstrations kept of tried, and rows ``tshix`` and
    ``ergodic`` (empty when the teacher recorded none; ``why`` then says why)."""

    variant: Variant
    kept: int
    tried: int
    rows: tuple[Row, ...]
    why: str = ""

    def rate(self, method: str) -> float | None:
        """Success rate of ``method`` (None: not run)."""
        row = next((r for r in self.rows if r.method == method), None)
        return None if row is None else row.ours.rate


def variant_demos(variant: Variant, seed: int) -> tuple[list[Demonstration], int, str]:
    """The teacher's demonstrations on ``variant``, how many it tried, and why it failed
    (``""`` when it recorded all it needed)."""
    task = variant.make()
    if variant.task == "socket3d":
        demos, discarded = record_socket_demos(task, seed)
        why = discarded[-1] if len(demos) < 2 and discarded else ""
        return demos, len(demos) + len(discarded), why
    teacher = BlindTeacher(task, seed=seed)
    try:
        demos, discarded = teacher.record(1)
    except TeachfitError as exc:
        return [], 5, str(exc)
    return demos, len(demos) + len(discarded), ""


def run_variant(
    variant: Variant,
    seed: int = 0,
    n_starts: int = 20,
    n_points: int | None = None,
    workers: int | None = None,
    progress: Progress = None,
    ergodic: bool = True,
    passes: int = 1,
) -> VariantResult:
    """Record, fit and run one variant (see the module docstring); ``ergodic=False`` runs
    the goal's TSHIX row only (half the executions); ``passes`` > 1: a TSHIX tour that ends
    without the hole goes on through fresh samples (:meth:`TshixPlanner.extend`), up to that
    many tours in all."""
    protocol, default_points, need = PROTOCOLS[variant.task]
    points = n_points or default_points
    demos, tried, why = variant_demos(variant, seed)
    if len(demos) < need:
        for _ in range((2 if ergodic else 1) * n_starts):
            if progress is not None:
                progress()
        return VariantResult(variant, len(demos), tried, (), why or "too few demonstrations")
    task = variant.make()
    model = SearchModel.fit(demos, task.name)
    rng = np.random.default_rng(seed + 1)
    starts = task.protocol.protocol_starts(protocol, n_starts, rng, demos[0].start_pose)
    seeds = [episode_seed(seed, i) for i in range(n_starts)]
    ov = dict(variant.overrides)
    tshix = _jobs(task.name, ov, model, starts, "tshix", points, seeds, passes=passes)
    res_t = run_jobs(tshix, workers, progress)
    rows = [_row("tshix", res_t, None)]
    if ergodic:
        length = float(np.mean([r.weighted_length for r in res_t]))
        erg = _jobs(task.name, ov, model, starts, "ergodic", points, seeds, length=length)
        rows.append(_row("ergodic", run_jobs(erg, workers, progress), None))
    return VariantResult(variant, len(demos), tried, tuple(rows))


def run_variants(
    task: str,
    n_variants: int = 12,
    seed: int = 0,
    n_starts: int = 20,
    n_points: int | None = None,
    workers: int | None = None,
    progress: Progress = None,
    ergodic: bool = True,
    on_variant: Callable[[VariantResult], None] | None = None,
    passes: int = 1,
) -> list[VariantResult]:
    """:func:`run_variant` on ``n_variants`` grid points of ``task`` drawn with ``seed``;
    ``on_variant`` gets each variant's result as soon as it is done (to print and save it:
    a long run stopped early keeps the variants it finished)."""
    if task not in PROTOCOLS:
        raise TeachfitError(f"no variant benchmark for {task!r}; choose from {sorted(PROTOCOLS)}")
    if n_starts < 1:
        raise TeachfitError(f"number of starts must be >= 1, got {n_starts}")
    out = []
    for v in sample_variants(task, n_variants, seed):
        out.append(run_variant(v, seed, n_starts, n_points, workers, progress, ergodic, passes))
        if on_variant is not None:
            on_variant(out[-1])
    return out


def goal_misses(results: Sequence[VariantResult]) -> list[VariantResult]:
    """The variants whose TSHIX success is below the goal for their task (or not run)."""
    return [
        r
        for r in results
        if (rate := r.rate("tshix")) is None or rate < GOALS[r.variant.task] - 1e-9
    ]


def figure_data(results: Sequence[VariantResult]) -> list[VariantRecord]:
    """Plain per-variant records for :func:`teachfit.viz.variant_figures.success_by_parameter`:
    the axis values, and per method ``(successes, trials, low, high)``."""
    out: list[VariantRecord] = []
    for r in results:
        rates = {
            row.method: (row.ours.successes, row.ours.trials, row.ours.low, row.ours.high)
            for row in r.rows
        }
        out.append({"values": dict(r.variant.values), "rates": rates})
    return out


def results_json(results: Sequence[VariantResult]) -> str:
    """The results as a JSON document: per variant its label, axis values, demonstrations
    kept/tried, the teacher's failure (``why``) and per method ``successes``, ``trials`` and
    the Wilson 95 % interval ``low``, ``high``."""
    doc = [
        {
            "variant": r.variant.label,
            "values": dict(r.variant.values),
            "demos_kept": r.kept,
            "demos_tried": r.tried,
            "why": r.why,
            "rates": {
                m: dict(zip(("successes", "trials", "low", "high"), v, strict=True))
                for m, v in fig["rates"].items()
            },
        }
        for r, fig in zip(results, figure_data(results), strict=True)
    ]
    return json.dumps(doc, indent=1)
