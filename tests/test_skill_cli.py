"""``teachfit skill show|run`` through typer's CliRunner."""

import pytest
from typer.testing import CliRunner

from teachfit.cli import app

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_skill_show_prints_and_plots_the_graph(tmp_path):
    png, toml = tmp_path / "skill.png", tmp_path / "skill.toml"
    res = invoke("skill", "show", "peg-in-hole", "--plot", png, "--toml", toml)
    assert res.exit_code == 0, res.output
    for word in ("approach", "contact", "lateral", "align", "insert", "retract", "alpha_t"):
        assert word in res.output
    assert png.stat().st_size > 20_000
    res = invoke("skill", "show", toml, "--controller", "impedance")  # the TOML loads back
    assert res.exit_code == 0, res.output
    res = invoke("skill", "show", "screw-in")
    assert res.exit_code == 2 and "unknown skill 'screw-in'" in res.output


def test_skill_run_with_params_plot_and_render(tmp_path):
    best = tmp_path / "best.toml"
    best.write_text("force = 10.0\nspeed_factor = 0.8\n")
    plot, video = tmp_path / "run.png", tmp_path / "run.mp4"
    res = invoke(
        "skill",
        "run",
        "peg-in-hole",
        "--task",
        "peg2d",
        "--params",
        best,
        "--controller",
        "impedance",
        "--starts",
        "1",
        "--seed",
        "3",
        "--plot",
        plot,
        "--render",
        video,
        "--fps",
        "5",
        "--width",
        "160",
        "--height",
        "120",
    )
    if res.exit_code == 2 and "rendering is unavailable" in res.output:
        pytest.skip("no OpenGL on this machine")
    assert res.exit_code == 0, res.output
    assert "1/1 succeeded" in res.output and "sim steps/s" in res.output
    assert plot.stat().st_size > 10_000 and video.stat().st_size > 1000


def test_skill_run_rejects_unknown_or_out_of_domain_params(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("force = 10.0\nforse = 3.0\n")
    res = invoke("skill", "run", "--task", "peg2d", "--params", bad, "--starts", "1")
    assert res.exit_code == 2 and "forse" in res.output and "unknown" in res.output
    far = tmp_path / "far.toml"
    far.write_text("tilt = 1.0\n")
    res = invoke("skill", "run", "--task", "peg2d", "--params", far, "--starts", "1")
    assert res.exit_code == 2 and "'tilt' = 1.0 is outside" in res.output
