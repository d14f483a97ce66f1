"""Same physics, same answer? The peg skill on ``--robot fr3`` (in-process) and through libfranka's
protocol on the Franka twin (``--robot franka``), the same seeds.

Usage: ``python benchmarks/twin_vs_fr3.py [--trials 10] [--seed 0] [--task peg]
[--markdown FILE]``

Both sides run the peg-in-hole skill with its default parameters from the same ``--trials``
start poses of one set-up (:func:`teachfit.execution.skill_trial.peg_in_hole_setup` with
``--seed``; the taught hole's error and the starts drawn from it), one execution each. The
fr3 side is the task's FR3 cell in this process (its sensor noise seeded with ``--seed``); the
franka side is the teachfit driver over pylibfranka against ``teachfit robot twin`` (the same
cell behind libfranka's protocol), which this script starts on 127.0.0.1 in lock-step
(``--no-realtime``, its seed ``--seed``) and stops by its PID. libfranka's port 1337 is fixed:
the script waits for the machine-wide lock the tests take on it.

Columns: successes k/n with Wilson 95 % intervals and whether the two intervals overlap; the
executions a safety reflex stopped; the wrench the skill sees (the log's measured force at
100 Hz, world frame): the mean of |F| over the executions' rows in contact (|F| >= 1 N), and
the per-execution peak |F| and peak lateral |F_xy|, their means over the executions. What
differs by construction: the fr3 robot's reset puts the arm at the start (a simulation's free
reset), the driver's reset drives it there through the cell (joint friction stops it up to
~1 mm off, the starts differ by that); the driver's law runs in its own 1 kHz loop and reads
libfranka's estimate (``O_F_ext_hat_K``) where the fr3 robot reads its observer directly;
the firmware's gravity model does not carry the held part (33 g on ``peg``: 0.3 N down).
``--markdown FILE`` appends the table with its provenance header.
"""

from __future__ import annotations

import argparse
import fcntl
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import numpy as np

from teachfit.cli.script_markdown import add_markdown_option, append_table, checked_markdown, table
from teachfit.core.errors import TeachfitError
from teachfit.core.outcome import Outcome
from teachfit.execution.engine_types import ExecutionResult
from teachfit.execution.skill_trial import SkillTrial, peg_in_hole_setup
from teachfit.metrics.stats import wilson_interval
from teachfit.tasks.registry import load_task

HEADER = ("robot", "success", "95 % interval", "reflexes", "mean ‖F‖ in contact",
          "peak ‖F‖", "peak ‖F_xy‖", "wall")  # fmt: skip
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


def run_side(robot: str, task: str, seed: int, trials: int) -> Side:
    """The skill's default parameters from each of the set-up's ``trials`` starts."""
    setup = peg_in_hole_setup(load_task(task), seed, trials)
    arm = {"host": "127.0.0.1", "realtime": False} if robot == "franka" else {}
    t0 = time.monotonic()
    trial = SkillTrial(setup, robot=robot, seed=seed, **arm)
    traces = []
    try:
        for i in range(trials):
            tr = trial.run(None, setup.starts[i], setup.frame(i))
            traces.append(tr)
            print(f"  {robot} {i}: {tr.outcome.value} ({tr.reason[:70]})", flush=True)
    finally:
        trial.robot.close()
    ok = [tr.success for tr in traces]
    reflex = [tr.reflex or tr.outcome is Outcome.FAULT for tr in traces]
    mean, peak, lateral = _figures(traces)
    return Side(robot, ok, reflex, mean, peak, lateral, time.monotonic() - t0)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--trials", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--task", default="peg")
    add_markdown_option(ap)
    args = ap.parse_args(argv)
    if args.trials < 1:
        ap.exit(2, f"error: --trials {args.trials}: give at least 1\n")
    markdown = checked_markdown(ap, args.markdown)
    try:
        load_task(args.task)
    except TeachfitError as exc:
        ap.exit(2, f"error: --task {args.task}: {exc}\n")
    fr3 = run_side("fr3", args.task, args.seed, args.trials)
    with twin(args.task, args.seed):
        franka = run_side("franka", args.task, args.seed, args.trials)
    rows = [fr3.row(), franka.row()]
    (a_lo, a_hi), (b_lo, b_hi) = fr3.interval(), franka.interval()
    overlap = "overlap" if a_lo <= b_hi and b_lo <= a_hi else "do not overlap"
    print("| " + " | ".join(HEADER) + " |")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    print(f"the 95 % intervals {overlap}")
    title = (
        f"**The peg skill (default parameters) on {args.task}: fr3 in-process vs the franka "
        f"driver on the twin**, the same {args.trials} starts (seed {args.seed}); the 95 % "
        f"intervals {overlap}"
    )
    append_table(ap, markdown, table(title, HEADER, rows))


if __name__ == "__main__":
    main()
