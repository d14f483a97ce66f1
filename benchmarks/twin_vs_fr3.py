"""Same physics, same answer? fr3 in-process vs the franka driver on the Franka twin, the same
seeds.

Usage: ``python benchmarks/twin_vs_fr3.py [--trials 10] [--seed 0]
[--cases peg,tshix-peg2d,assemble-peg2d] [--points 100] [--fr3-cell twin|own] [--markdown FILE]``

Each case runs ``--trials`` executions on ``--robot fr3`` (the task's FR3 cell in this process,
its sensor noise seeded with ``--seed``; ``--fr3-cell twin``, the default, places its base and
the held part where the twin's cell has them, :func:`~teachfit.robot.franka.twin_cell.cell_params`:
the base 0.25 m below the world origin and the part at libfranka's flange-to-EE offset, 103.4 mm,
so that the two sides differ in the protocol path only; ``own`` keeps the fr3 robot's defaults,
base at the origin and part at 66 mm) and then the same ones on ``--robot franka``: teachfit's
driver over pylibfranka against ``teachfit robot twin`` (the same cell behind libfranka's
protocol), which this script starts on 127.0.0.1 in lock-step (``--no-realtime``, its seed
``--seed``) and stops by its PID. libfranka's port 1337 is fixed: the script waits for the
machine-wide lock the tests take on it. Cases:

* ``peg``: the peg-in-hole skill with its default parameters from the ``--trials`` starts of
  one set-up (:func:`teachfit.execution.skill_trial.peg_in_hole_setup` with ``--seed``: the
  taught hole's error and the starts), one execution each;
* ``tshix-peg2d``: TSHIX (``--points`` N, 100 by default; feed-forward on) from ``--trials``
  of Table I's starts on ``peg2d``, the model learned from one seeded teacher demonstration
  recorded on the fr3 robot (both sides search with it; the samples are drawn per start from
  ``--seed``);
* ``assemble-peg2d``: ``teachfit assemble``'s joined skill (peg-in-hole with the learned
  search as its recovery, that same model) on ``peg2d`` with the taught hole
  :data:`HOLE_ERROR` off in a seeded direction per trial, as ``assemble --hole-error 2mm``.

Columns: successes k/n with Wilson 95 % intervals and whether the two sides' intervals
overlap; the executions a safety reflex (or another robot fault) stopped; the wrench the method
sees (the log's measured force at 100 Hz, world frame): the mean of ‖F‖ over the rows in
contact (‖F‖ >= 1 N) and the per-execution peak ‖F‖ and peak lateral ‖F_xy‖, their means over
the executions; wall time. What differs by construction: the fr3 robot's reset puts the arm at
the start (a simulation's free reset), the driver's drives it there through the cell (joint
friction stops it up to ~1 mm off); the driver's law runs in its own 1 kHz thread, its
apparent mass from libfranka's mass matrix at each reset, and reads libfranka's estimate where
the fr3 robot's runs in the physics step with the operational-space inertia. ``--markdown FILE``
appends the table with its provenance header.
"""

from __future__ import annotations

import argparse
import fcntl
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import cache
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from teachfit.cli.script_markdown import add_markdown_option, append_table, checked_markdown, table
from teachfit.core.geometry import Pose
from teachfit.core.outcome import Outcome
from teachfit.execution.engine_types import ExecutionResult
from teachfit.execution.search import run_protocol
from teachfit.execution.skill_trial import SkillTrial, peg_in_hole_setup
from teachfit.execution.teacher import BlindTeacher
from teachfit.metrics.stats import wilson_interval
from teachfit.models.search_model import SearchModel
from teachfit.robot.registry import make_robot
from teachfit.tasks.base import Task
from teachfit.tasks.registry import load_task

#: TSHIX's sample count (``--points``)
POINTS = [100]
#: the fr3 side's cell (``--fr3-cell``): the twin's base and part mount, or the fr3 robot's own
FR3_CELL = ["twin"]
#: a robot's options (``--robot franka``: host and realtime)
Arm = dict[str, Any]

HEADER = ("case", "robot", "success", "95 % interval", "reflexes", "mean ‖F‖ in contact",
          "peak ‖F‖", "peak ‖F_xy‖", "wall", "intervals overlap")  # fmt: skip
#: the tests' machine-wide hold on 127.0.0.1:1337 (tests/franka_fixtures.py)
PORT_LOCK = Path(tempfile.gettempdir()) / "teachfit-franky-sim.lock"
CONTACT_N = 1.0


class Side(NamedTuple):
    """One robot's executions: per execution success, reflex and the wrench figures (N)."""

    robot: str
    success: list[bool]
    reflex: list[bool]
    contact_mean: float
    peak: list[float]
    peak_lateral: list[float]
    wall: float

    def interval(self) -> tuple[float, float]:
        return wilson_interval(sum(self.success), len(self.success))

    def row(self) -> list[str]:
        k, n = sum(self.success), len(self.success)
        lo, hi = self.interval()
        return [
            self.robot,
            f"{k}/{n}",
            f"[{100 * lo:.0f}, {100 * hi:.0f}] %",
            str(sum(self.reflex)),
            f"{self.contact_mean:.1f} N",
            f"{np.mean(self.peak):.1f} N",
            f"{np.mean(self.peak_lateral):.1f} N",
            f"{self.wall:.0f} s",
        ]


@contextmanager
def twin(task: str, seed: int) -> Iterator[None]:
    """The Franka twin of ``task`` on 127.0.0.1 (lock-step), under the port's lock; stopped by
    its PID on the way out."""
    from teachfit.robot.franka.twin import TwinProcess

    with PORT_LOCK.open("w") as lock:
        print(f"waiting for 127.0.0.1:1337 ({PORT_LOCK})", flush=True)
        fcntl.flock(lock, fcntl.LOCK_EX)
        proc = TwinProcess(task, realtime=False, seed=seed)
        proc.start()
        print(f"twin of {task!r} started, PID {proc.pid}", flush=True)
        try:
            yield
        finally:
            proc.stop()
            fcntl.flock(lock, fcntl.LOCK_UN)


def _figures(traces: list[ExecutionResult]) -> tuple[float, list[float], list[float]]:
    """Mean |F| over the rows in contact, per-execution peak |F| and peak |F_xy| (N)."""
    rows = np.concatenate([np.linalg.norm(t.log.wrench[:, :3], axis=1) for t in traces])
    touching = rows[rows >= CONTACT_N]
    peak = [float(np.linalg.norm(t.log.wrench[:, :3], axis=1).max()) for t in traces]
    lateral = [float(np.linalg.norm(t.log.wrench[:, :2], axis=1).max()) for t in traces]
    return float(touching.mean()) if touching.size else 0.0, peak, lateral


def _peg_runs(name: str, arm: Arm, task: Task, seed: int, trials: int) -> list[ExecutionResult]:
    """The peg skill's default parameters from each of the set-up's ``trials`` starts."""
    setup = peg_in_hole_setup(task, seed, trials)
    trial = SkillTrial(setup, robot=name, seed=seed, **arm)
    try:
        return [_said(trial.run(None, setup.starts[i], setup.frame(i))) for i in range(trials)]
    finally:
        trial.robot.close()


@cache
def _tshix_model(task: Task, seed: int) -> tuple[Pose, SearchModel]:
    """One seeded teacher's demonstration on the fr3 robot and its model (both sides search
    with it): the demonstration's start (Table I's anchor) and the model."""
    demos, _ = BlindTeacher(task, seed=seed, robot="fr3").record(1)
    return demos[0].start_pose, SearchModel.fit(demos, task.name)


def _tshix_runs(name: str, arm: Arm, task: Task, seed: int, trials: int) -> list[ExecutionResult]:
    """TSHIX (N = ``POINTS[0]``) from ``trials`` of Table I's starts, the samples drawn per
    start."""
    start, model = _tshix_model(task, seed)
    robot = make_robot(name, task, seed=seed, **arm)
    try:
        runs = run_protocol(
            robot, task, model, "tshix", POINTS[0], trials, "table1", seed, demo_start=start,
            on_done=lambda run: _said(run.result),
        )  # fmt: skip
    finally:
        robot.close()
    return [r.result for r in runs]


#: the taught hole's error of the ``assemble-peg2d`` case (m)
HOLE_ERROR = 0.002


def _assemble_runs(
    name: str, arm: Arm, task: Task, seed: int, trials: int
) -> list[ExecutionResult]:
    """``assemble``'s joined skill, the taught hole :data:`HOLE_ERROR` off, ``trials`` trials
    (trial ``i``'s direction and start drawn from ``seed`` as ``assemble`` draws them)."""
    from teachfit.execution.assembly import assembly_jobs, close_robots, run_assembly_job

    _, model = _tshix_model(task, seed)
    jobs = assembly_jobs(
        task.name, ["joined"], [HOLE_ERROR], trials, model, seed=seed, robot=name,
        keep_log=True, robot_options=tuple(arm.items()),
    )  # fmt: skip
    try:
        done = [run_assembly_job(job) for job in jobs]
    finally:
        close_robots()
    return [_said(t.result) for t in done if t.result is not None]


#: case -> (task, runs): what each side runs
CASES: dict[str, tuple[str, Callable[[str, Arm, Task, int, int], list[ExecutionResult]]]] = {
    "peg": ("peg", _peg_runs),
    "tshix-peg2d": ("peg2d", _tshix_runs),
    "assemble-peg2d": ("peg2d", _assemble_runs),
}


def _said(result: ExecutionResult) -> ExecutionResult:
    """Print one execution's outcome; return it."""
    print(f"  {result.outcome.value} ({result.reason[:70]})", flush=True)
    return result


def fr3_cell() -> Arm:
    """The fr3 robot's options of ``--fr3-cell``: the twin's base and part mount (``twin``) or
    none (``own``)."""
    if FR3_CELL[0] == "own":
        return {}
    from teachfit.robot.franka.twin_cell import TwinParams, cell_params

    cell = cell_params(TwinParams())
    return {"base_pos": cell.base_pos, "mount_offset": cell.mount_offset}


def run_side(case: str, robot: str, seed: int, trials: int) -> Side:
    """``case``'s executions on ``robot`` (``franka``: the driver on 127.0.0.1)."""
    task_name, runs = CASES[case]
    arm: Arm = {"host": "127.0.0.1", "realtime": False} if robot == "franka" else fr3_cell()
    t0 = time.monotonic()
    print(f"{case} on {robot}", flush=True)
    traces = runs(robot, arm, load_task(task_name), seed, trials)
    ok = [tr.success for tr in traces]
    reflex = [tr.reflex or tr.outcome is Outcome.FAULT for tr in traces]
    mean, peak, lateral = _figures(traces)
    return Side(robot, ok, reflex, mean, peak, lateral, time.monotonic() - t0)


def _case_rows(case: str, seed: int, trials: int) -> list[list[str]]:
    """Both sides of ``case`` (fr3 first, then the franka driver on a twin of its task): a
    row each, the second saying whether the intervals overlap."""
    fr3 = run_side(case, "fr3", seed, trials)
    with twin(CASES[case][0], seed):
        franka = run_side(case, "franka", seed, trials)
    (a_lo, a_hi), (b_lo, b_hi) = fr3.interval(), franka.interval()
    overlap = "yes" if a_lo <= b_hi and b_lo <= a_hi else "no"
    return [[case, *fr3.row(), ""], [case, *franka.row(), overlap]]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--trials", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--points", type=int, default=100, help="TSHIX points (tshix-peg2d)")
    ap.add_argument(
        "--fr3-cell",
        choices=("twin", "own"),
        default="twin",
        help="the fr3 side's base and part mount: the twin's (default) or the fr3 robot's own",
    )
    add_markdown_option(ap)
    args = ap.parse_args(argv)
    if args.trials < 1:
        ap.exit(2, f"error: --trials {args.trials}: give at least 1\n")
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    unknown = [c for c in cases if c not in CASES]
    if unknown or not cases:
        ap.exit(2, f"error: --cases {args.cases}: known cases are {', '.join(CASES)}\n")
    if args.points < 1:
        ap.exit(2, f"error: --points {args.points}: give at least 1\n")
    POINTS[0] = args.points
    FR3_CELL[0] = args.fr3_cell
    markdown = checked_markdown(ap, args.markdown)
    rows = []
    for case in cases:
        rows += _case_rows(case, args.seed, args.trials)
    print("| " + " | ".join(HEADER) + " |")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    what = {
        "peg": "the peg skill's default parameters on peg",
        "tshix-peg2d": f"TSHIX (N = {args.points}) on peg2d",
        "assemble-peg2d": f"the joined skill on peg2d, hole {HOLE_ERROR * 1e3:g} mm off",
    }
    cell = {"twin": "the twin's cell geometry", "own": "its own cell geometry"}
    title = (
        f"**fr3 in-process vs the franka driver on the twin**, the same {args.trials} starts "
        f"per case (seed {args.seed}), the fr3 robot in {cell[args.fr3_cell]}: "
        + "; ".join(what[c] for c in cases)
    )
    append_table(ap, markdown, table(title, HEADER, rows))


if __name__ == "__main__":
    main()
