"""Executions per CPU-second of the learning grid's executions, two code versions, same outcomes.

Usage: ``python benchmarks/exec_per_cpu.py --label NAME --out FILE.json [--tasks puzzle,key,peg]
[--executions 24] [--seed 0] [--repeats 3]`` runs a fixed list of executions and writes them;
``python benchmarks/exec_per_cpu.py --compare A.json B.json [--markdown FILE]`` compares two
such files.

The executions are those of ``teachfit bench learning``'s grid: the peg-in-hole skill with the
adaptive controller on the floating robot, per task one set-up (``SkillObjective(task,
seed)``: hole estimate, four starts, sensor noise) and ``--executions`` parameter sets drawn
uniformly in the skill's learned domain from ``--seed``, execution ``i`` from start ``i mod 4``.
One untimed execution first loads the compiled tick. Each task's list runs ``--repeats`` times,
the robot's sensor-noise stream restarted from ``--seed`` each time;
its CPU time (``time.process_time``: this process, all threads) is the least of the repeats, so
that other jobs on a shared machine inflate it less, and every repeat must give the same
fingerprints (else the file is not written).

A fingerprint per execution: the outcome, the time to success in control ticks, the ticks run
and the final TCP position in micrometres (rounded to 1e-6 m). To compare the code of two
commits, run the script once with ``PYTHONPATH`` at each commit's ``src`` (e.g. ``git archive
BASE src | tar -x -C /tmp/base``) and ``--compare`` the two files: executions/CPU-s of each,
their ratio per task and overall, and the number of executions whose fingerprints differ (each
difference is printed). ``--markdown FILE`` appends the comparison table with its provenance
header (:mod:`teachfit.cli.script_markdown`).

On a shared machine the CPU time of one version varies between runs: two runs of the same code
(commit a172637, the 2-core machine with three other jobs) gave ratios of 1.05, 1.11 and 1.13
per task; a ratio means something beyond that noise only, the fingerprints exactly.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from teachfit.cli.common import check_output
from teachfit.cli.script_markdown import add_markdown_option, append_table, checked_markdown, table
from teachfit.core.atomic import atomic_write_text
from teachfit.core.errors import TeachfitError


class NotFixed(RuntimeError):
    """The same executions gave other fingerprints when run again (not deterministic)."""


#: the learning grid's tasks (``teachfit bench learning --tasks puzzle,key,peg``)
TASKS = ("puzzle", "key", "peg")


def fixed_params(space: Any, n: int, seed: int) -> list[dict[str, float]]:
    """``n`` parameter sets uniform in ``space``'s unit cube (its log domains in log scale)."""
    rng = np.random.default_rng(seed)
    return [space.from_unit(rng.uniform(size=space.dim)) for _ in range(n)]


def fingerprint(result: Any, pos: np.ndarray, period: float) -> dict[str, Any]:
    """What must not change between two code versions: outcome, time to success (ticks; None
    without success), ticks run, final TCP position (µm, rounded)."""
    t = float(result.time_to_success)
    return {
        "outcome": result.outcome.name,
        "success_tick": round(t / period) if np.isfinite(t) else None,
        "ticks": int(result.steps),
        "pos_um": [round(float(v) * 1e6) for v in pos],
    }


def run_task(task: str, n: int, seed: int, repeats: int) -> dict[str, Any]:
    """The fixed executions of ``task`` run ``repeats`` times: least CPU seconds, fingerprints."""
    from teachfit.learning.objective import SkillObjective

    obj = SkillObjective(task, seed=seed)
    trial = obj.trial()
    setup, robot = trial.setup, trial.robot
    params = fixed_params(obj.space, n, seed)
    period = float(robot.control_period)
    trial.run(params[0], setup.starts[0], setup.frame(0))  # load the compiled tick, untimed
    best, prints = float("inf"), None
    for _ in range(repeats):
        robot.rng = np.random.default_rng(seed)  # the sensor noise drawn afresh: same stream
        got = []
        cpu0 = time.process_time()
        for i, values in enumerate(params):
            k = i % len(setup.starts)
            result = trial.run(values, setup.starts[k], setup.frame(k))
            got.append(fingerprint(result, robot.state().pos, period))
        best = min(best, time.process_time() - cpu0)
        if prints is not None and got != prints:
            raise NotFixed(f"{task}: the repeats gave other fingerprints; nothing written")
        prints = got
    return {
        "cpu_s": best,
        "params": [{k: float(f"{v:.12g}") for k, v in p.items()} for p in params],
        "fingerprints": prints,
    }


def load_run(ap: argparse.ArgumentParser, path: Path) -> dict[str, Any]:
    """A file this script wrote; else one line and exit status 2."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        ap.exit(2, f"error: --compare {path}: cannot read it ({exc}); give a file --out wrote\n")
    if not isinstance(data, dict) or not isinstance(data.get("tasks"), dict):
        ap.exit(2, f"error: --compare {path}: no 'tasks' in it; give a file --out wrote\n")
    return data


def differences(task: str, a: list[dict], b: list[dict]) -> list[str]:
    """One line per execution whose fingerprints differ between two runs."""
    lines = []
    for i, (fa, fb) in enumerate(zip(a, b, strict=True)):
        if fa != fb:
            moved = max(abs(x - y) for x, y in zip(fa["pos_um"], fb["pos_um"], strict=True))
            lines.append(f"{task} #{i}: {fa} != {fb} (final position {moved} µm apart)")
    return lines


def compare(
    ap: argparse.ArgumentParser, run_a: Mapping[str, Any], run_b: Mapping[str, Any]
) -> tuple[list[list[str]], list[str]]:
    """Table rows (per task, then all) and the differing executions of two runs."""
    ta, tb = run_a["tasks"], run_b["tasks"]
    if sorted(ta) != sorted(tb):
        ap.exit(2, f"error: --compare: the runs have other tasks ({sorted(ta)}, {sorted(tb)})\n")
    rows, diffs, sums = [], [], np.zeros(3)
    for task in ta:
        a, b = ta[task], tb[task]
        if a["params"] != b["params"]:
            ap.exit(2, f"error: --compare: {task} ran other parameter sets; same --seed needed\n")
        n = len(a["fingerprints"])
        found = differences(task, a["fingerprints"], b["fingerprints"])
        diffs += found
        sums += (n, a["cpu_s"], b["cpu_s"])
        rows.append(_row(task, n, a["cpu_s"], b["cpu_s"], len(found)))
    rows.append(_row("all", int(sums[0]), sums[1], sums[2], len(diffs)))
    return rows, diffs


def _row(name: str, n: int, cpu_a: float, cpu_b: float, differ: int) -> list[str]:
    rates = (f"{n / cpu_a:.2f}", f"{n / cpu_b:.2f}", f"{cpu_a / cpu_b:.2f}")
    return [name, str(n), *rates, str(differ)]


def write_run(args: argparse.Namespace) -> None:
    """Run the fixed executions of every task and write them to ``args.out``."""
    tasks = [t for t in args.tasks.split(",") if t]
    out: dict[str, Any] = {"label": args.label, "seed": args.seed, "tasks": {}}
    for task in tasks:
        res = run_task(task, args.executions, args.seed, args.repeats)
        out["tasks"][task] = res
        n = len(res["fingerprints"])
        ok = sum(f["outcome"] == "SUCCESS" for f in res["fingerprints"])
        print(f"{args.label} {task}: {n} executions ({ok} succeeded), {res['cpu_s']:.2f} CPU-s, "
              f"{n / res['cpu_s']:.2f} executions/CPU-s")  # fmt: skip
    atomic_write_text(args.out, json.dumps(out, indent=1) + "\n", "run file")
    print(f"written to {args.out}")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--label", help="name of this code version (with --out)")
    ap.add_argument("--out", type=Path, help="JSON file of the run's CPU time and fingerprints")
    ap.add_argument("--tasks", default=",".join(TASKS))
    ap.add_argument("--executions", type=int, default=24, help="executions per task")
    ap.add_argument("--seed", type=int, default=0, help="set-up and parameter seed")
    ap.add_argument("--repeats", type=int, default=3, help="runs of each task's list (least CPU)")
    ap.add_argument("--compare", nargs=2, type=Path, metavar=("A", "B"), help="two --out files")
    add_markdown_option(ap)
    args = ap.parse_args(argv)
    markdown = checked_markdown(ap, args.markdown)
    if args.compare is None:
        if args.out is None or not args.label:
            ap.exit(2, "error: give --label NAME --out FILE (a run) or --compare A B\n")
        if args.executions < 1 or args.repeats < 1:
            ap.exit(2, "error: --executions and --repeats must be >= 1\n")
        try:
            check_output(args.out, "out")
            write_run(args)
        except (NotFixed, TeachfitError) as exc:
            ap.exit(2, f"error: {exc}\n")
        return
    run_a, run_b = (load_run(ap, p) for p in args.compare)
    rows, diffs = compare(ap, run_a, run_b)
    la, lb = run_a.get("label", "A"), run_b.get("label", "B")
    head = ["task", "executions", f"{la} exec/CPU-s", f"{lb} exec/CPU-s", "ratio", "differ"]
    text = table(f"**Executions per CPU-second, {la} vs {lb}**", head, rows)
    print(text)
    print("\n".join(diffs) if diffs else "every execution's fingerprint is the same")
    append_table(ap, markdown, text)


if __name__ == "__main__":
    main()
