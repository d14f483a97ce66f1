"""Seed A's search experiments reproduced in simulation, beside the paper's numbers.

Table I: one demonstration; 30 starts in a 3 cm circle halfway between the demonstration's
start and the hole; TSHIX (300 points, a new trajectory per start) vs. one ergodic trajectory of
about the mean TSHIX length, both with the GMR feed-forward.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from teachfit.demonstrations.teacher import BlindTeacher
from teachfit.execution.search import plan_search, run_search
from teachfit.metrics.stats import SuccessSummary, summarize
from teachfit.models.search_model import SearchModel
from teachfit.pose import Pose
from teachfit.robot.floating import FloatingToolRobot
from teachfit.tasks.registry import get_task

#: the paper's real-robot results (successes, trials)
PAPER_TABLE1 = {"tshix": (25, 30), "ergodic": (20, 30)}


@dataclass(frozen=True)
class Row:
    method: str
    ours: SuccessSummary
    paper: tuple[int, int]
    plan_ms: float


def table1(
    seed: int = 0,
    n_starts: int = 30,
    n_points: int = 300,
    clearance: float = 0.0005,
    progress: Callable[[str], None] | None = None,
) -> list[Row]:
    """Run Table I's protocol; returns one row per method."""
    task = get_task("peg2d", clearance=clearance)
    demos, _ = BlindTeacher(task, seed=seed).record(1)
    demo = demos[0]
    model = SearchModel.fit(demos, task.name)
    rng = np.random.default_rng(seed + 1)
    starts = task.protocol_starts("table1", n_starts, rng, Pose(demo.pos[0], demo.quat[0]))
    robot = FloatingToolRobot(task, seed=seed)
    rows = []
    tshix_lengths = []
    results: dict[str, list] = {"tshix": [], "ergodic": []}
    plan_ms: dict[str, list[float]] = {"tshix": [], "ergodic": []}
    for i, start in enumerate(starts):
        t0 = time.perf_counter()
        traj = plan_search(model, "tshix", n_points, np.random.default_rng(seed * 1000 + i))
        plan_ms["tshix"].append(1e3 * (time.perf_counter() - t0))
        tshix_lengths.append(traj.path_length())
        results["tshix"].append(run_search(robot, task, model, start, traj).outcome)
        if progress:
            progress("tshix")
    t0 = time.perf_counter()
    ergodic = plan_search(
        model,
        "ergodic",
        n_points,
        np.random.default_rng(seed),
        length=float(np.mean(tshix_lengths)),
    )
    plan_ms["ergodic"].append(1e3 * (time.perf_counter() - t0))
    for start in starts:
        results["ergodic"].append(run_search(robot, task, model, start, ergodic).outcome)
        if progress:
            progress("ergodic")
    for method, outcomes in results.items():
        s = summarize([o.success for o in outcomes], [o.time_to_insertion for o in outcomes])
        rows.append(Row(method, s, PAPER_TABLE1[method], float(np.median(plan_ms[method]))))
    return rows
