"""CLI of demonstration-guided planning (typer app of teachfit.cli.plan_cmd)."""

import numpy as np
from rich.console import Console
from typer.testing import CliRunner

from teachfit.cli.plan_cmd import app, bench_planning
from teachfit.plans import build_assembly
from teachfit.viz.plan_video import render_path_video

runner = CliRunner()


def test_parts_show_prints_dimensions_and_plots(tmp_path):
    png = tmp_path / "parts.png"
    result = runner.invoke(app, ["parts", "show", "l-groove", "--plot", str(png)])
    assert result.exit_code == 0, result.output
    assert "opening_length" in result.output and "70.0" in result.output
    assert png.stat().st_size > 1000
    bad = runner.invoke(app, ["parts", "show", "peg"])
    assert bad.exit_code == 2 and "unknown task" in bad.output


def test_synth_then_plan_with_demo_writes_figures(tmp_path):
    h5 = tmp_path / "l_demo.h5"
    result = runner.invoke(
        app, ["demo", "synth", "--task", "l-groove", "--seed", "3", "--out", str(h5)]
    )
    assert result.exit_code == 0, result.output
    strip, keys, npy = tmp_path / "strip.png", tmp_path / "keys.png", tmp_path / "path.npy"
    result = runner.invoke(
        app,
        [
            "plan",
            "--task",
            "l-groove",
            "--demo",
            str(h5),
            "--strip",
            str(strip),
            "--keyposes",
            str(keys),
            "--save",
            str(npy),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "success" in result.output
    assert strip.stat().st_size > 1000 and keys.stat().st_size > 1000
    path = np.load(npy)
    assert path.shape[1] == 7 and len(path) >= 2
    # a demonstration of other parts is refused with a clear message
    wrong = runner.invoke(app, ["plan", "--task", "tenon", "--demo", f"{h5}:0"])
    assert wrong.exit_code == 2 and "l-groove" in wrong.output


def test_plan_needs_exactly_one_of_demo_and_no_demo():
    result = runner.invoke(app, ["plan", "--task", "tenon"])
    assert result.exit_code == 2
    result = runner.invoke(app, ["plan", "--task", "tenon", "--no-demo", "--te", "0.02"])
    assert result.exit_code == 1 and "failure" in result.output


def test_video_is_written(tmp_path):
    asm = build_assembly("tenon")
    from teachfit.plans import matrix_to_state

    path = np.stack([matrix_to_state(asm.start), matrix_to_state(asm.goal)])
    out = render_path_video(asm, path, tmp_path / "p.mp4", frames=3, size_px=160)
    assert out.stat().st_size > 500


def test_bench_planning_prints_and_appends(tmp_path):
    md = tmp_path / "BENCHMARKS.md"
    console = Console(record=True, width=160)
    results = bench_planning(
        ["tenon"], 1, no_demo_seeds=1, no_demo_budget=0.05, write=True, benchmarks=md, out=console
    )
    assert results[0].demo.n == 1 and results[0].no_demo.n == 1
    text = console.export_text()
    assert "speed-up" in text and "paper" in text
    assert "| tenon | demo |" in md.read_text()
