import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from teachfit.cli import app

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def test_tasks_lists_parameters():
    res = invoke("tasks")
    assert res.exit_code == 0, res.output
    assert "peg2d" in res.output and "clearance" in res.output and "socket3d" in res.output


def test_record_show_render_round_trip(tmp_path):
    demos = tmp_path / "demos.h5"
    res = invoke("demo", "record", "--task", "peg2d", "-n", "1", "--seed", "1", "--out", demos)
    assert res.exit_code == 0, res.output
    assert demos.exists()
    res = invoke("demo", "show", demos, "--plot", tmp_path / "demos.png")
    assert res.exit_code == 0, res.output
    assert "simulated-teacher" in res.output
    assert (tmp_path / "demos.png").stat().st_size > 10_000
    res = invoke("demo", "record", "--task", "peg2d", "-n", "1", "--out", demos)
    assert res.exit_code == 2 and "exists" in res.output  # never overwrites silently
    out = tmp_path / "demo0.mp4"
    res = invoke(
        "render",
        "--task",
        "peg2d",
        "--demo",
        f"{demos}:0",
        "--out",
        out,
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
    assert out.stat().st_size > 1000


def test_import_csv_and_clear_errors(tmp_path):
    out = tmp_path / "demos.h5"
    res = invoke(
        "demo",
        "import",
        EXAMPLES / "robot_log.csv",
        "--task",
        "peg2d",
        "--columns",
        EXAMPLES / "columns.toml",
        "--out",
        out,
    )
    assert res.exit_code == 0, res.output
    assert "imported" in res.output
    bad = tmp_path / "bad.csv"
    text = (EXAMPLES / "robot_log.csv").read_text().splitlines()
    cells = text[5].split(",")
    cells[2] = "nan"
    text[5] = ",".join(cells)
    bad.write_text("\n".join(text) + "\n")
    res = invoke(
        "demo",
        "import",
        bad,
        "--task",
        "peg2d",
        "--columns",
        EXAMPLES / "columns.toml",
        "--out",
        tmp_path / "other.h5",
    )
    assert res.exit_code == 2
    assert "row 6" in res.output.replace("\n", " ")
    assert not (tmp_path / "other.h5").exists()  # nothing half-written


def test_unknown_task_is_a_clear_error(tmp_path):
    res = invoke("demo", "record", "--task", "peg9d", "--out", tmp_path / "x.h5")
    assert res.exit_code == 2 and "unknown task" in res.output


def test_quickstart_small(tmp_path):
    res = invoke("quickstart", "--out", tmp_path, "--demos", "1", "--starts", "2")
    assert res.exit_code == 0, res.output
    assert "What this showed" in res.output
    assert (tmp_path / "replay.png").exists() and (tmp_path / "demos.h5").exists()


def test_bench_sim_prints_ratio():
    res = invoke("bench", "sim", "--steps", "300", "--repeats", "1")
    assert res.exit_code == 0, res.output
    assert "ratio" in res.output and "real-time factor" in res.output


def test_console_script_installed():
    import sys

    beside = Path(sys.executable).parent / "teachfit"
    assert beside.exists() or shutil.which("teachfit") is not None


def test_learn_plan_run_search(tmp_path):
    demos = tmp_path / "demos.h5"
    assert invoke("demo", "record", "-n", "1", "--seed", "1", "--out", demos).exit_code == 0
    model = tmp_path / "peg.model"
    res = invoke("learn", "search", demos, "--out", model)
    assert res.exit_code == 0, res.output
    res = invoke(
        "search", "plan", model, "--method", "tshix", "-n", "50", "--plot", tmp_path / "plan.png"
    )
    assert res.exit_code == 0, res.output
    assert "ergodic metric" in res.output and (tmp_path / "plan.png").exists()
    res = invoke(
        "search",
        "run",
        "--task",
        "peg2d",
        "--model",
        model,
        "-n",
        "50",
        "--starts",
        "1",
        "--demo",
        f"{demos}:0",
    )
    assert res.exit_code == 0, res.output
    assert "starts" in res.output
    res = invoke("search", "run", "--task", "socket3d", "--model", model, "--starts", "1")
    assert res.exit_code == 2  # a peg2d model for the socket task
    other = tmp_path / "socket.h5"
    assert invoke("demo", "record", "--task", "socket3d", "-n", "1", "--out", other).exit_code == 0
    res = invoke("search", "run", "--model", model, "--starts", "1", "--demo", f"{other}:0")
    assert res.exit_code == 2 and "socket3d" in res.output
    res = invoke("search", "run", "--model", model, "--method", "ergodic", "--passes", "2")
    assert res.exit_code == 2 and "passes" in res.output
    res = invoke("search", "figures", model, "--out", tmp_path / "figs", "-n", "40")
    assert res.exit_code == 0, res.output
    names = {"samples.png", "tshix_stages.png", "feedforward.png", "planned_vs_executed.png"}
    assert names <= {f.name for f in (tmp_path / "figs").iterdir()}


def test_bench_search_names_missing_tables():
    res = invoke("bench", "search", "--table", "7")
    assert res.exit_code == 2 and "available" in res.output
