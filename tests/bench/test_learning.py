"""``teachfit bench learning``: tasks x methods x experiments, statistics, figures."""

from __future__ import annotations

import dataclasses
import math
import os
import signal
from pathlib import Path

import numpy as np
import pytest
from media_checks import read_png
from scipy import stats
from typer.testing import CliRunner

from teachfit.bench.learning import (
    PAPER_ORDERING,
    BenchInterrupted,
    ordering,
    paired_markdown,
    run_learning_bench,
    to_markdown,
    unsolved_setups,
)
from teachfit.cli import app
from teachfit.learning.objective import SkillObjective
from teachfit.viz.learning_figures import plot_best_execution, plot_learning_curves


def test_bench_statistics_agree_with_the_experiments(tmp_path: Path) -> None:
    seen: list[str] = []
    bench = run_learning_bench(
        ["key"],
        ["cmaes", "lhs"],
        2,
        6,
        workers=0,
        n_starts=1,
        seed=5,
        on_trial=lambda label, _r: seen.append(label),
    )
    assert len(seen) == 2 * 2 * 6 and seen[0] == "key/cmaes #1"
    assert [(c.task, c.method, c.n) for c in bench.cells] == [
        ("key", "cmaes", 2),
        ("key", "lhs", 2),
    ]
    for cell in bench.cells:
        exps = [e for e in bench.experiments if e.method == cell.method]
        assert [e.seed for e in exps] == [5, 6] and all(len(e.costs) == 6 for e in exps)
        best = [e.costs[e.best_index] for e in exps]
        assert math.isclose(cell.best_cost_mean, float(np.mean(best)))
        assert math.isclose(cell.best_cost_sd, float(np.std(best, ddof=1)))
        assert cell.curve.mean.shape == (6,)
        assert math.isclose(cell.curve.mean[-1], cell.best_cost_mean)
        assert np.all(cell.curve.low <= cell.curve.mean + 1e-12)
        total = np.mean([sum(e.sim_s) / 60 for e in exps])
        assert math.isclose(cell.sim_total_min, float(total))
        assert cell.sim_best_min <= cell.sim_total_min
        firsts = [e.first_feasible for e in exps]
        assert cell.never_feasible == firsts.count(None)
        found = [k for k in firsts if k is not None]
        if found:  # some set-ups (hole estimates) are hard: nothing feasible in 6 trials
            assert math.isclose(cell.first_feasible_mean, float(np.mean(found)))
        else:
            assert math.isnan(cell.first_feasible_mean) and math.isnan(cell.insertion_time)
        # wall figures are printed by the benchmark; here only their arithmetic is checked
        assert math.isclose(cell.wall_s, float(np.mean([e.wall_s for e in exps])))
        assert math.isclose(cell.trials_per_s, 12 / sum(e.wall_s for e in exps))
        # the mean best cost's 95 % t interval over the 2 experiments, and every execution
        half = 12.706 * cell.best_cost_sd / math.sqrt(2)
        assert math.isclose(cell.best_cost_high - cell.best_cost_mean, half, rel_tol=1e-3)
        assert cell.executions == 12
        ok = sum(round(r) for e in exps for r in e.success_rate)
        assert cell.executions_ok == ok
    text = to_markdown(bench)
    rows = [ln for ln in text.splitlines() if ln.startswith("| key |")]
    assert [r.split(" | ")[1] for r in rows] == ["cmaes", "lhs"]
    for row, cell in zip(rows, bench.cells, strict=True):
        assert f"| {100 * cell.best_success:.0f} % |" in row
        assert f"{cell.best_cost_mean:.3f} [{cell.best_cost_low:.3f}, " in row
        assert f"| {cell.n - cell.never_feasible}/2 | {cell.executions_ok}/12 = " in row
    assert "- ordering on key (mean best cost, s): **" in text
    # paired: the difference of the two methods' best costs on each common set-up (seed)
    lo, hi = sorted(bench.cells, key=lambda c: c.best_cost_mean)
    by = {(e.method, e.seed): e.costs[e.best_index] for e in bench.experiments}
    d = [by[(hi.method, s)] - by[(lo.method, s)] for s in (5, 6)]
    half = float(stats.t.ppf(0.975, 1)) * float(np.std(d, ddof=1)) / math.sqrt(2)
    paired = paired_markdown(bench)
    assert paired in text and paired.startswith(f"- paired on key: {hi.method} - {lo.method} = ")
    assert f"= {np.mean(d):+.3f} [{np.mean(d) - half:+.3f}, " in paired
    assert "over 2 set-ups" in paired and f"Paper: {PAPER_ORDERING['key']}" in paired
    # a set-up no method solved is named; one that a single method solved is not
    never = [dataclasses.replace(e, feasible=(False,) * 6) for e in bench.experiments]
    assert unsolved_setups(dataclasses.replace(bench, experiments=tuple(never)), "key") == [5, 6]
    one = [never[0], *never[1:]]
    one[0] = dataclasses.replace(never[0], feasible=(True,) + (False,) * 5)
    solved = [e.seed for e in one if e.first_feasible is not None]
    fixed = dataclasses.replace(bench, experiments=tuple(one))
    assert unsolved_setups(fixed, "key") == [s for s in (5, 6) if s not in solved]
    assert "no method succeeded once" in paired_markdown(fixed)
    # ordering: "<" only between intervals that do not overlap
    a, b = bench.cells
    apart = [
        dataclasses.replace(a, best_cost_mean=1.0, best_cost_low=0.9, best_cost_high=1.1),
        dataclasses.replace(b, best_cost_mean=2.0, best_cost_low=1.5, best_cost_high=2.5),
    ]
    assert ordering(apart) == {"key": "cmaes < lhs"}
    close = [dataclasses.replace(apart[0], best_cost_high=1.6), apart[1]]
    assert ordering(close[::-1]) == {"key": "cmaes ≈ lhs"}
    path = plot_learning_curves(
        {(c.task, c.method): c.curve for c in bench.cells}, tmp_path / "fig6.png"
    )
    read_png(path, min_px=300)


def test_an_interrupted_grid_resumes_from_its_studies(tmp_path: Path) -> None:
    seen: list[str] = []

    def interrupt(label: str, _r: object) -> None:
        seen.append(label)
        if len(seen) == 1:  # Ctrl-C during the first experiment, after its first trial
            os.kill(os.getpid(), signal.SIGINT)

    kw = {"workers": 0, "n_starts": 1, "studies": tmp_path}
    with pytest.raises(BenchInterrupted, match="key/cmaes seed 0 interrupted; its 1 finished"):
        run_learning_bench(["key"], ["cmaes"], 2, 2, on_trial=interrupt, **kw)
    assert len(list(tmp_path.glob("*.db"))) == 1  # the grid stopped there
    whole = run_learning_bench(["key"], ["cmaes"], 2, 2, on_trial=interrupt, **kw)
    assert len(seen) == 1 + 1 + 2  # the stored trial was kept, not run again
    assert [e.restored for e in whole.experiments] == [1, 0]
    assert len(list(tmp_path.glob("key-cmaes-s*.db"))) == 2
    fresh = run_learning_bench(["key"], ["cmaes"], 1, 2, workers=0, n_starts=1)
    assert whole.experiments[0].costs == fresh.experiments[0].costs


def _bench(*args: str) -> object:
    return CliRunner().invoke(app, ["bench", "learning", "--tasks", "key", "--no-target", *args])


def test_bench_learning_cli_and_best_execution_figure(tmp_path: Path) -> None:
    md, fig = tmp_path / "bench.md", tmp_path / "curves.png"
    res = _bench(
        *("--methods", "lhs", "--experiments", "2", "--trials", "3", "--starts", "1"),
        *("--workers", "0", "--speedup-trials", "0", "--plot", str(fig), "--markdown", str(md)),
        *("--out", str(tmp_path / "studies")),
    )
    assert res.exit_code == 0, res.output
    # the table written is the library's for the same settings, but for the wall-time columns
    expected = to_markdown(run_learning_bench(["key"], ["lhs"], 2, 3, workers=0, n_starts=1))
    row = next(ln for ln in md.read_text().splitlines() if ln.startswith("| key | lhs |"))
    want = next(ln for ln in expected.splitlines() if ln.startswith("| key | lhs |"))
    assert row.split(" | ")[:7] == want.split(" | ")[:7]
    read_png(fig, min_px=300)
    assert "per CPU-s" in res.output and len(list((tmp_path / "studies").glob("*.db"))) == 2
    res = _bench("--methods", "sgd", "--experiments", "1", "--trials", "2")
    assert res.exit_code == 2 and "unknown method(s) ['sgd']" in res.output
    obj = SkillObjective("key", n_starts=1)
    trace = obj.outcome(None).traces[0]
    read_png(plot_best_execution(trace, tmp_path / "best.png"), min_px=300)


def test_setups_count_every_execution_and_held_out_gets_its_column() -> None:
    """Trials over two set-ups count 2 x starts executions each; the best parameters then run
    on held-out set-ups, reported beside the training success."""
    bench = run_learning_bench(
        ["peg2d"], ["lhs"], 1, 2, workers=0, n_starts=1, setups=2, held_out=3
    )
    (exp,) = bench.experiments
    (cell,) = bench.cells
    assert cell.executions == 2 * 2 and len(exp.held_out) == 3
    assert cell.held_out == 3 and cell.held_out_ok == sum(exp.held_out)
    text = to_markdown(bench)
    assert "best on held-out set-ups [95 % Wilson]" in text
    assert f"| {cell.held_out_ok}/3 = " in text
    plain = run_learning_bench(["peg2d"], ["lhs"], 1, 1, workers=0, n_starts=1)
    assert "held-out" not in to_markdown(plain)  # the table keeps its shape without them
