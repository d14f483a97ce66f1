import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from media_checks import read_png, read_video
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.demonstrations.csv_import import ColumnMap, import_csv
from teachfit.demonstrations.dataset import (
    Demonstration,
    dataset_summary,
    read_dataset,
    write_dataset,
)

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def _flat(text: str) -> str:
    return " ".join(text.split())


def _still_demo(task: str, n: int = 50) -> Demonstration:
    """A short demonstration of ``task`` holding still at 100 Hz (a file of another task)."""
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    pos, wrench = np.zeros((n, 3)), np.zeros((n, 6))
    return Demonstration(np.arange(n) / 100.0, pos, quat, wrench, task=task, source="synthetic")


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """One peg2d demonstration recorded through the CLI, and the command's result."""
    demos = tmp_path_factory.mktemp("rec") / "demos.h5"
    res = invoke("demo", "record", "--task", "peg2d", "-n", "1", "--seed", "1", "--out", demos)
    return demos, res


def test_tasks_lists_parameters():
    res = invoke("tasks")
    assert res.exit_code == 0, res.output
    assert "peg2d" in res.output and "clearance" in res.output and "socket3d" in res.output


def test_record_show_round_trip(recorded, tmp_path):
    demos, res = recorded
    assert res.exit_code == 0, res.output
    assert f"recorded 1 demonstration(s) of peg2d -> {demos}" in _flat(res.output)
    (demo,) = read_dataset(demos)
    assert demo.task == "peg2d" and demo.source == "simulated-teacher" and demo.n_samples > 10
    res = invoke("demo", "show", demos, "--plot", tmp_path / "demos.png")
    assert res.exit_code == 0, res.output
    (row,) = dataset_summary(demos)
    line = next(ln for ln in res.output.splitlines() if row["name"] in ln)
    for cell in ("simulated-teacher", str(row["samples"]), f"{row['duration']:.2f} s"):
        assert cell in line, cell
    read_png(tmp_path / "demos.png", min_px=300)
    res = invoke("demo", "record", "--task", "peg2d", "-n", "1", "--out", demos)
    assert res.exit_code == 2 and "exists" in res.output  # never overwrites silently
    np.testing.assert_array_equal(read_dataset(demos)[0].pos, demo.pos)


def _moving_demo(task: str, n: int = 120) -> Demonstration:
    """A 1.2 s demonstration of ``task`` at 100 Hz: 20 mm across and 20 mm down onto the hole."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    pos = (1.0 - s) * np.array([0.02, 0.0, 0.02])
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    return Demonstration(
        np.arange(n) / 100.0, pos, quat, np.zeros((n, 6)), task=task, source="synthetic"
    )


def test_render_writes_the_recorded_motion(tmp_path, needs_gl):
    demos = write_dataset(tmp_path / "moving.h5", [_moving_demo("peg2d")])
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
    assert res.exit_code == 0, res.output
    (demo,) = read_dataset(demos)
    n_frames = len(np.arange(demo.t[0], demo.t[-1] + 1e-9, 1.0 / 5))  # one frame per 1/fps s
    frames = read_video(out)
    assert frames.shape == (n_frames, 120, 160, 3)
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).max() > 40  # it moves


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
    columns = ColumnMap.from_toml(EXAMPLES / "columns.toml")
    lib = import_csv(EXAMPLES / "robot_log.csv", columns, task="peg2d")
    flat = _flat(res.output)
    assert "imported 1 demonstration(s)" in flat
    row = f"{lib.duration:.2f} │ {lib.n_samples} │ {lib.meta['rate_hz']:g}"
    assert row in " ".join(flat.split()), flat
    (stored,) = read_dataset(out)
    np.testing.assert_array_equal(stored.pos, lib.pos)
    np.testing.assert_array_equal(stored.wrench, lib.wrench)
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
    res = invoke(
        "quickstart",
        "--out",
        tmp_path,
        "--count",
        "2",
        "--seed",
        "1",
        "--starts",
        "2",
        "--points",
        "10",
    )
    assert res.exit_code == 0, res.output
    out = _flat(res.output)
    assert "from all 2 demonstrations" in out and "What this showed" in out
    each = r"replay [01]/1, tshix [01]/1, random-walk [01]/1"  # one start of each kind
    assert re.search(rf"from new starts: {each}; with the hole moved \d+-\d+ mm: {each}\.", out)
    read_png(tmp_path / "replay.png", min_px=200)
    assert len(read_dataset(tmp_path / "demos.h5")) == 2


def test_quickstart_needs_two_demonstrations(tmp_path):
    res = invoke("quickstart", "--out", tmp_path, "--count", "1")
    assert res.exit_code == 2 and "--count must be >= 2" in res.output


def test_bench_sim_prints_ratio():
    res = invoke("bench", "sim", "--steps", "300", "--repeats", "1")
    assert res.exit_code == 0, res.output
    out = _flat(res.output)
    contacts = re.search(r"in contact \((\d+) contacts\)", out)
    assert contacts is not None and int(contacts.group(1)) >= 1
    raw, ctl = (
        float(re.search(rf"{label}\W+([0-9,]+) steps/s", out).group(1).replace(",", ""))
        for label in ("raw mj_step", "with controller")
    )
    ratio = float(re.search(r"ratio\W+([0-9.]+)", out).group(1))
    assert ratio == pytest.approx(ctl / raw, abs=0.006)  # the printed ratio is of those two
    assert re.search(r"real-time factor\W+[0-9.]+x", out)


def test_console_script_runs_the_installed_package():
    import subprocess
    import sys

    import teachfit

    beside = Path(sys.executable).parent / "teachfit"
    exe = str(beside) if beside.exists() else shutil.which("teachfit")
    assert exe is not None, "the teachfit console script is not installed"
    out = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == f"teachfit {teachfit.__version__}"


def test_learn_plan_run_search(tmp_path):
    demos = tmp_path / "demos.h5"
    assert invoke("demo", "record", "-n", "1", "--seed", "1", "--out", demos).exit_code == 0
    model = tmp_path / "peg.model"
    res = invoke("learn", "search", demos, "--out", model)
    assert res.exit_code == 0, res.output
    even = invoke("learn", "search", demos, "--out", tmp_path / "x.model", "--mirror", "x")
    assert even.exit_code == 0 and "2 component(s)" in even.output, even.output
    assert "made even in x" in even.output and "made even" not in res.output
    bad = invoke("learn", "search", demos, "--out", tmp_path / "rz.model", "--mirror", "rz")
    assert bad.exit_code == 2 and "cannot mirror ['rz']" in bad.output
    assert not (tmp_path / "rz.model").exists()
    res = invoke(
        "search", "plan", model, "--method", "tshix", "-n", "50", "--plot", tmp_path / "plan.png"
    )
    assert res.exit_code == 0, res.output
    assert "ergodic metric" in res.output
    read_png(tmp_path / "plan.png", min_px=200)
    res = invoke(
        "search",
        "run",
        "--task",
        "peg2d",
        "--model",
        model,
        "-n",
        "30",
        "--starts",
        "1",
        "--demo",
        f"{demos}:0",
    )
    assert res.exit_code == 0, res.output
    assert "starts" in res.output
    res = invoke("search", "run", "--task", "socket3d", "--model", model, "--starts", "1")
    assert res.exit_code == 2  # a peg2d model for the socket task
    other = write_dataset(tmp_path / "socket.h5", [_still_demo("socket3d")])  # another task's
    res = invoke("search", "run", "--model", model, "--starts", "1", "--demo", f"{other}:0")
    assert res.exit_code == 2 and "socket3d" in res.output
    res = invoke("search", "run", "--model", model, "--method", "ergodic", "--passes", "2")
    assert res.exit_code == 2 and "passes" in res.output
    res = invoke("search", "figures", model, "--out", tmp_path / "figs", "-n", "40")
    assert res.exit_code == 0, res.output
    names = {"samples.png", "tshix_stages.png", "feedforward.png", "planned_vs_executed.png"}
    assert names <= {f.name for f in (tmp_path / "figs").iterdir()}
    for name in names:
        read_png(tmp_path / "figs" / name, min_px=200)


def test_bench_search_names_missing_tables():
    res = invoke("bench", "search", "--table", "7")
    assert res.exit_code == 2 and "available" in res.output


def test_bench_search_methods_are_rows_of_one_table():
    res = invoke("bench", "search", "--table", "3", "--methods", "tshix,spiral")
    assert res.exit_code == 2 and "Table III has no method 'tshix'" in _flat(res.output)
    res = invoke("bench", "search", "--table", "2", "--methods", "tshix")
    assert res.exit_code == 2 and "--table 1 or --table 3" in _flat(res.output)


def test_bench_search_variants_refuses_what_it_cannot_run(tmp_path):
    res = invoke("bench", "search", "--variants", "2", "--table", "2")
    assert res.exit_code == 2 and "--table 1, 3 or all" in res.output
    bad = tmp_path / "fig.xyz"
    res = invoke("bench", "search", "--variants", "2", "--plot", bad)
    assert res.exit_code == 2 and "fig.xyz" in _flat(res.output) and not bad.exists()
    res = invoke("bench", "search", "--table", "1", "--passes", "2")
    assert res.exit_code == 2 and "--passes is for --variants" in _flat(res.output)
