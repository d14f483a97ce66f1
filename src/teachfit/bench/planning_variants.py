"""Guided planning on parameter variants of the planning tasks (``bench planning --variants``).

A seeded sample of the grid: clearance per side between 0.5 mm and the task's default, every
other dimension scaled by one factor in [0.9, 1.1]. Each variant runs the same
planner with the same settings as the default task (nothing tuned per variant), on synthetic
demonstrations of that variant. Reported per variant: success, median planning time, key poses
used, and the demonstration samples in collision outside the deliberate push (0: the script
and its tremor clear the variant's parts).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import cast

import numpy as np

from teachfit.core.errors import PlanningError, TeachfitError
from teachfit.plans.planner import MotionPlanner, PlannerConfig
from teachfit.plans.synth import synth_demo
from teachfit.tasks.parts import PARTS
from teachfit.tasks.registry import build_assembly

__all__ = [
    "CLEARANCE_RANGE",
    "SCALE_RANGE",
    "VARIANT_COLUMNS",
    "VariantResult",
    "run_variants",
    "sample_variants",
    "variant_rows",
]

CLEARANCE_RANGE: tuple[float, float] = (0.0005, 1.0)
"""Clearance per side (m) from 0.5 mm up to the task's default (the upper bound is a factor of
the default: 1.0 = the default itself)."""
SCALE_RANGE: tuple[float, float] = (0.9, 1.1)
"""Factor on every dimension but the clearance."""


def sample_variants(task: str, n: int, seed: int = 0) -> list[dict[str, float]]:
    """``n`` seeded variants of ``task`` as dimension overrides (m); the first three are the
    tightest clearance on the default, the smallest and the largest parts."""
    if task not in PARTS:
        raise PlanningError(f"unknown task {task!r}; known: {', '.join(PARTS)}")
    if n < 1:
        raise PlanningError(f"variants must be >= 1, got {n}")
    base = PARTS[task]()
    names = [f.name for f in dataclasses.fields(base) if f.name != "clearance"]
    default_clearance = float(base.clearance)
    rng = np.random.default_rng(seed)
    picks = [(CLEARANCE_RANGE[0], s) for s in (1.0, SCALE_RANGE[0], SCALE_RANGE[1])]
    while len(picks) < n:
        c = rng.uniform(CLEARANCE_RANGE[0], default_clearance * CLEARANCE_RANGE[1])
        picks.append((float(c), float(rng.uniform(*SCALE_RANGE))))
    out = []
    for clearance, scale in picks[:n]:
        over = {name: float(getattr(base, name)) * scale for name in names}
        out.append(over | {"clearance": clearance})
    return out


@dataclass(frozen=True)
class VariantResult:
    """One variant's guided runs (times in s, clearance in m)."""

    task: str
    clearance: float
    scale: float
    runs: int
    success_rate: float
    time_median: float
    used_min: int
    used_max: int
    script_collisions: int
    error: str = ""


def _scale_of(task: str, over: Mapping[str, float]) -> float:
    base = PARTS[task]()
    name = next(f.name for f in dataclasses.fields(base) if f.name != "clearance")
    return over[name] / float(getattr(base, name))


def run_variants(
    tasks: tuple[str, ...],
    n: int,
    runs: int,
    config: PlannerConfig,
    progress: Callable[[str, int], None] | None = None,
) -> list[VariantResult]:
    """``n`` variants per task, ``runs`` seeds each (demonstration and planner seed 0 ..
    runs - 1). A variant whose parts cannot be built or whose start/goal collide is reported
    with its error instead of aborting the sweep."""
    out = []
    for task in tasks:
        for k, over in enumerate(sample_variants(task, n)):
            label = f"{task} variant {k + 1}/{n}"
            clearance, scale = over["clearance"], _scale_of(task, over)
            try:
                asm = build_assembly(task, **over)
                mp = MotionPlanner(asm, config)
            except TeachfitError as exc:  # a variant that cannot be built is its own result
                out.append(VariantResult(task, clearance, scale, 0, 0.0, 0.0, 0, 0, 0, str(exc)))
                continue
            results, collisions = [], 0
            for seed in range(runs):
                collisions = max(
                    collisions,
                    cast(int, synth_demo(asm, seed, p_penetrate=0.0).meta["n_colliding"]),
                )
                results.append(mp.plan(synth_demo(asm, seed), seed=seed))
                if progress:
                    progress(label, seed + 1)
            used = [r.used_key_poses for r in results if r.success] or [0]
            out.append(
                VariantResult(
                    task=task,
                    clearance=clearance,
                    scale=scale,
                    runs=runs,
                    success_rate=float(np.mean([r.success for r in results])),
                    time_median=float(np.median([r.time_s for r in results])),
                    used_min=min(used),
                    used_max=max(used),
                    script_collisions=collisions,
                )
            )
    return out


VARIANT_COLUMNS = (
    "task",
    "clearance (mm)",
    "size",
    "runs",
    "success",
    "median time (s)",
    "key poses used",
    "demo samples colliding (no push)",
)


def variant_rows(results: list[VariantResult]) -> list[list[str]]:
    """Rows of the variant table (columns :data:`VARIANT_COLUMNS`)."""
    rows = []
    for r in results:
        head = [r.task, f"{1e3 * r.clearance:.2f}", f"x{r.scale:.3f}"]
        if r.error:
            rows.append(head + ["0", f"error: {r.error}", "-", "-", "-"])
            continue
        rows.append(
            head
            + [
                str(r.runs),
                f"{100 * r.success_rate:.0f} %",
                f"{r.time_median:.3f}",
                f"{r.used_min}-{r.used_max}",
                str(r.script_collisions),
            ]
        )
    return rows
