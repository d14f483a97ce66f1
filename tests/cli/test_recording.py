"""``--log`` / ``--rrd`` on ``search run`` and ``skill run``, read back by ``demo show`` (its
``--plot`` is the test of :mod:`teachfit.viz.run_figures`)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from media_checks import read_png
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.demonstrations.dataset import Demonstration, write_dataset
from teachfit.execution.recording import read_run_log
from teachfit.models.search_model import SearchModel

runner = CliRunner()


def invoke(*args: object):
    return runner.invoke(app, [str(a) for a in args])


def flat(text: str) -> str:
    return "".join(text.split())


@pytest.fixture(scope="module")
def model_file(tmp_path_factory) -> Path:
    """A peg2d search model from a made-up 2 s demonstration (no teacher run: it is slow)."""
    rng = np.random.default_rng(0)
    n = 200
    t = np.arange(n) / 250.0  # a brisk teacher: short searches
    xy = np.cumsum(rng.normal(size=(n, 2)) * 2e-4 + [1e-4, 0.5e-4], axis=0)
    pos = np.column_stack([xy, np.zeros(n)])
    vel = np.gradient(xy, t, axis=0)
    f = -5.0 * vel / (np.linalg.norm(vel, axis=1, keepdims=True) + 1e-9)
    wrench = np.column_stack([f, -10 * np.ones(n), np.zeros((n, 3))])
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    demo = Demonstration(t, pos, quat, wrench, task="peg2d", source="synthetic")
    return SearchModel.fit([demo], "peg2d").save(tmp_path_factory.mktemp("m") / "peg.model")


def test_search_run_log_then_demo_show(model_file: Path, tmp_path: Path) -> None:
    log, rrd = tmp_path / "runs" / "run.h5", tmp_path / "run.rrd"
    rerun = ["--rrd", rrd] if importlib.util.find_spec("rerun") else []  # the optional extra
    res = invoke(
        "search", "run", "--model", model_file, "-n", 5, "--starts", 2, "--seed", 4,
        "--log", log, *rerun,
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "runlog->" in flat(res.output)
    run = read_run_log(log)
    assert (run.info.kind, run.info.task, run.info.method, run.info.seed) == (
        "search",
        "peg2d",
        "tshix",
        4,
    )
    assert run.info.options["starts"] == 2 and run.info.options["log"] == str(log)
    assert len(run.episodes) == 2 and all(ep.planned is not None for ep in run.episodes)
    assert rerun == [] or rrd.stat().st_size > 1000
    res = invoke("demo", "show", log, "--plot", tmp_path / "run.png")
    assert res.exit_code == 0, res.output
    text = flat(res.output)
    assert "runlogofsearchtshixonpeg2d" in text and "finaldepth" in text
    outcome = run.episodes[0].result.outcome.value
    assert f"0│{'success' if run.episodes[0].result.success else outcome}" in text
    assert f"{sum(e.result.success for e in run.episodes)}/2episodessucceeded" in text
    read_png(tmp_path / "run.png", min_px=400)


def test_bad_targets_are_refused_before_the_robot_moves(model_file, tmp_path, monkeypatch) -> None:
    t = np.linspace(0, 1, 5)
    quat = np.tile([1.0, 0, 0, 0], (5, 1))
    demo = Demonstration(t, np.zeros((5, 3)), quat, None, task="peg2d", source="synthetic")
    demos = write_dataset(tmp_path / "demos.h5", [demo])
    before = demos.read_bytes()
    res = invoke("search", "run", "--model", model_file, "--starts", 1, "--log", demos)
    assert res.exit_code == 2 and res.output.count("error:") == 1 and "Traceback" not in res.output
    assert "notarunlog" in flat(res.output) and "starts" not in res.output  # nothing ran
    assert demos.read_bytes() == before
    monkeypatch.setitem(sys.modules, "rerun", None)  # as without the optional extra
    res = invoke("skill", "run", "--starts", 1, "--rrd", tmp_path / "k.rrd")
    assert res.exit_code == 2 and "pipinstall'teachfit[rerun]'" in flat(res.output)
    assert "executions" not in res.output and not (tmp_path / "k.rrd").exists()


def test_skill_run_log_records_primitives(tmp_path: Path) -> None:
    log = tmp_path / "skill.h5"
    res = invoke("skill", "run", "--task", "peg", "--starts", 1, "--log", log)
    assert res.exit_code == 0, res.output
    (ep,) = read_run_log(log).episodes
    visited = [v.node for v in ep.result.visits]
    assert visited[0] == "approach" and set(visited) <= set(ep.primitives)
    assert ep.start is not None and np.isfinite(ep.result.log.setpoint_quat).all()
    names = ep.result.node_names
    assert {names[i] for i in set(ep.result.log.node.tolist()) if i >= 0} <= set(visited)
