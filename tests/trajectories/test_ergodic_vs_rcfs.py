"""The RCFS spectral-multiscale-coverage comparator (``benchmarks/rcfs_smc.py``) and the default
ergodic planner against it (``benchmarks/ergodic_vs_rcfs.py``)."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from teachfit.trajectories.ergodic import ergodic_metric
from teachfit.trajectories.ergodic_opt import ergodic_search

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"


def _script(name: str, monkeypatch) -> ModuleType:
    monkeypatch.syspath_prepend(str(BENCH))  # as `python benchmarks/NAME.py` runs it
    spec = importlib.util.spec_from_file_location(name, BENCH / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_rcfs_smc_metric_decreases_over_time_on_a_gaussian(monkeypatch) -> None:
    bench = _script("ergodic_vs_rcfs", monkeypatch)
    rcfs = _script("rcfs_smc", monkeypatch)
    expl = bench.distributions()["Gaussian"]
    w_hat = rcfs.mixture_coefficients(expl.weights, expl.means, expl.covs)
    states, err = rcfs.smc_path(w_hat, bench.START, 10.0)
    walked = np.linalg.norm(np.diff(states, axis=0), axis=1).sum()
    assert 10.0 <= walked < 10.1  # runs until the path has the length
    # RCFS's own error and ours (16 coefficients) both fall along the path
    assert err[-1] < 0.2 * err[20]
    ours = [ergodic_metric(states[:n], expl, box=bench.BOX) for n in (25, 100, states.shape[0])]
    assert ours[0] > ours[1] > ours[2]


@pytest.mark.parametrize("length", [2.5, 10.0])
def test_default_ergodic_keeps_the_length_and_covers_better_than_rcfs(monkeypatch, length) -> None:
    bench = _script("ergodic_vs_rcfs", monkeypatch)
    expl = bench.distributions()["RCFS mixture"]
    traj = ergodic_search(expl, speed=1.0, length=length, start=bench.START, box=bench.BOX)
    assert traj.method == "ergodic" and traj.meta["optimiser_iterations"] > 0
    assert traj.path_length() == pytest.approx(length, rel=0.01)
    ours = ergodic_metric(traj.states, expl, t=traj.t, box=bench.BOX)
    assert ours == pytest.approx(traj.meta["ergodic_metric"])
    assert ours < ergodic_metric(bench._rcfs(expl, length), expl, box=bench.BOX)


def test_default_ergodic_keeps_the_length_with_rz_and_an_angular_speed() -> None:
    from teachfit.models.exploration import ExplorationDistribution

    cov = np.diag([1e-4, 4e-5, 0.01])
    expl = ExplorationDistribution(
        ("x", "y", "rz"), np.ones(1), np.array([[0.01, 0, 0.05]]), cov[None]
    )
    traj = ergodic_search(expl, speed=0.01, length=0.1, angular_speed=0.2, iterations=30)
    assert traj.path_length(traj.meta["length_scale"]) == pytest.approx(0.1, rel=0.01)


def test_the_comparison_script_appends_its_table(monkeypatch, tmp_path) -> None:
    from teachfit.cli import provenance as pv

    pv.new_run()
    md = tmp_path / "out.md"
    _script("ergodic_vs_rcfs", monkeypatch).main(["--lengths", "2.5", "--markdown", str(md)])
    body = md.read_text(encoding="utf-8")
    assert "**Ergodic metric against RCFS's SMC**" in body
    assert body.count("| Gaussian | 2.5 | ") == 1 and body.count("| RCFS mixture | 2.5 | ") == 1
