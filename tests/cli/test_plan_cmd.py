"""CLI of demonstration-guided planning (typer app of teachfit.cli.plan_cmd)."""

import re

import numpy as np
import pytest
from media_checks import read_png, read_video
from typer.testing import CliRunner

from teachfit.bench.planning import PlanningBenchConfig, report_table, run_planning_bench
from teachfit.cli.plan_cmd import app
from teachfit.core.errors import RenderError
from teachfit.core.geometry import Pose, poses_to_array
from teachfit.demonstrations.dataset import read_demo
from teachfit.plans import MotionPlanner, PlannerConfig, build_assembly
from teachfit.viz.plan_video import render_path_video

runner = CliRunner()


def _flat(text: str) -> str:
    return " ".join(text.split())


def test_parts_show_prints_the_library_dimensions_and_plots(tmp_path):
    png = tmp_path / "parts.png"
    result = runner.invoke(app, ["parts", "show", "l-groove", "--plot", str(png)])
    assert result.exit_code == 0, result.output
    asm = build_assembly("l-groove")
    lines = result.output.splitlines()
    for key, value in asm.dimensions.items():
        assert any(key in ln and f"{1e3 * value:.1f}" in ln for ln in lines), key
    assert f"moving part: {len(asm.moving.faces)} triangles" in result.output
    img = read_png(png, min_px=300)
    assert img.shape[1] > 2 * img.shape[0]  # three panels side by side
    bad = runner.invoke(app, ["parts", "show", "peg"])
    assert bad.exit_code == 2 and "unknown task" in bad.output


def test_plan_saves_the_path_the_library_plans(tmp_path):
    h5 = tmp_path / "l_demo.h5"
    result = runner.invoke(
        app, ["demo", "synth", "--task", "l-groove", "--seed", "3", "--out", str(h5)]
    )
    assert result.exit_code == 0, result.output
    strip, keys, npy = tmp_path / "strip.png", tmp_path / "keys.png", tmp_path / "path.npy"
    args = ["plan", "--task", "l-groove", "--demo", str(h5), "--max-checks", "1000"]
    args += ["--seed", "2", "--strip", str(strip), "--keyposes", str(keys), "--save", str(npy)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    # the same query through the library: the very same path and figures
    asm = build_assembly("l-groove")
    mp = MotionPlanner(asm, PlannerConfig(max_checks=1000))
    expected = mp.plan(read_demo(f"{h5}:0"), seed=2)
    assert expected.success
    assert np.array_equal(np.load(npy), poses_to_array(expected.poses))
    assert np.allclose(np.load(npy), expected.path, rtol=0, atol=1e-15)
    out = _flat(result.output)
    assert f"key poses used {expected.used_key_poses}/{expected.candidates}" in out
    assert f"{expected.collision_checks} collision checks" in out
    panels = read_png(strip, min_px=150)
    assert panels.shape[1] > 3 * panels.shape[0]  # six poses side by side
    read_png(keys, min_px=200)
    # a demonstration of other parts is refused with a clear message
    wrong = runner.invoke(app, ["plan", "--task", "tenon", "--demo", f"{h5}:0"])
    assert wrong.exit_code == 2 and "l-groove" in wrong.output


def test_plan_needs_exactly_one_of_demo_and_no_demo():
    result = runner.invoke(app, ["plan", "--task", "tenon"])
    assert result.exit_code == 2
    assert "give exactly one of --demo FILE and --no-demo" in result.output
    args = ["plan", "--task", "tenon", "--no-demo", "--max-checks", "300"]
    result = runner.invoke(app, args)
    assert result.exit_code == 1, result.output
    assert "failure: no path within 300 collision checks per attempt" in _flat(result.output)


def test_video_shows_the_part_moving(tmp_path):
    asm = build_assembly("tenon")
    path = (Pose.from_matrix(asm.start), Pose.from_matrix(asm.goal))
    out = render_path_video(asm, path, tmp_path / "p.mp4", frames=3, size_px=160)
    frames = read_video(out)
    assert frames.shape == (3, 160, 160, 3)
    moved = np.abs(frames[0].astype(int) - frames[-1].astype(int)).max(axis=2) > 40
    assert moved.mean() > 0.005  # the moving part is elsewhere in the last frame
    with pytest.raises(RenderError, match="Pose"):
        render_path_video(asm, np.zeros((2, 7)), tmp_path / "q.mp4")


def test_bench_planning_prints_and_appends_what_the_library_computes(tmp_path):
    md = tmp_path / "BENCHMARKS.md"
    args = ["bench", "planning", "--tasks", "tenon", "--seeds", "2", "--max-checks", "1000"]
    args += ["--no-demo-seeds", "1", "--no-demo-budget", "0.05", "--write"]
    result = runner.invoke(app, [*args, "--benchmarks", str(md)])
    assert result.exit_code == 0, result.output
    cfg = PlanningBenchConfig(
        tasks=("tenon",), seeds=2, max_checks=1000, no_demo_seeds=1, no_demo_budget=0.05
    )
    guided = report_table(run_planning_bench(cfg))[0]
    text = md.read_text()
    assert f"`{cfg.command()}`" in text
    row = next(ln for ln in text.splitlines() if ln.startswith("| tenon | demo |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    # runs, poses available, used and success do not depend on the machine's speed
    assert cells[:5] == guided[:5] and cells[8] == guided[8]
    assert guided[8].startswith("100 %") and "budget 1000 checks/attempt" in guided[8]
    assert any(ln.startswith("| tenon | no-demo | 1 |") for ln in text.splitlines())
    out = _flat(result.output)
    assert "tenon: speed-up with demonstration" in out and "tenon: speed-up" in text
    check = re.search(r"tenon: collision check ([0-9.]+) us per call", out)
    assert check is not None and float(check.group(1)) > 0
    bad = runner.invoke(app, ["bench", "planning", "--tasks", "peg"])
    assert bad.exit_code == 2 and "unknown or no task(s) ['peg']" in bad.output


def test_task_param_overrides_reach_the_parts_and_bad_ones_exit_2(tmp_path):
    ok = runner.invoke(app, ["parts", "show", "tenon", "--task-param", "clearance=0.0005"])
    assert ok.exit_code == 0, ok.output
    assert any("clearance" in ln and "0.5" in ln for ln in ok.output.splitlines())
    params = tmp_path / "p.toml"
    params.write_text("clearance = 0.0007\n", encoding="utf-8")
    both = ["parts", "show", "tenon", "--task-params", str(params)]
    assert any("0.7" in ln for ln in runner.invoke(app, both).output.splitlines() if "clear" in ln)
    for bad in (["--task-param", "bogus=1"], ["--task-param", "clearance"]):
        res = runner.invoke(app, ["parts", "show", "tenon", *bad])
        assert res.exit_code == 2 and len(res.output.strip().splitlines()) == 1, res.output
    params.write_text("clearance = 'tight'\n", encoding="utf-8")
    res = runner.invoke(app, both)
    assert res.exit_code == 2 and str(params) in _flat(res.output)


def test_bench_planning_runs_a_variant_sweep_into_the_markdown(tmp_path):
    md = tmp_path / "b.md"
    args = ["bench", "planning", "--tasks", "tenon", "--runs", "1", "--no-demo-runs", "0"]
    res = runner.invoke(app, [*args, "--variants", "1", "--markdown", str(md)])
    assert res.exit_code == 0, res.output
    text = md.read_text(encoding="utf-8")
    assert "--variants 1" in text and "| tenon | 0.50 | x1.000 | 1 |" in text
    bad = runner.invoke(app, [*args, "--task-param", "bar_side=-1"])
    assert bad.exit_code == 2 and "bar_side" in bad.output
