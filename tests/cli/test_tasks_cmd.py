"""``teachfit tasks``: list, example, new, show; bad input is one line and exit code 2."""

from __future__ import annotations

import tomllib
from pathlib import Path

from typer.testing import CliRunner

from teachfit.cli import app

runner = CliRunner()


def invoke(*args: object):
    return runner.invoke(app, [str(a) for a in args])


def test_tasks_alone_and_list_list_the_built_in_tasks() -> None:
    for args in (("tasks",), ("tasks", "list")):
        res = invoke(*args)
        assert res.exit_code == 0, res.output
        assert "peg2d" in res.output and "socket3d" in res.output and "tasks new" in res.output
        assert "l-groove" in res.output and "tenon" in res.output and "opening_length" in res.output


def test_new_infers_the_hole_and_show_reports_and_plots(mesh_examples, tmp_path: Path) -> None:
    folder = Path(mesh_examples["square-peg"]).parent
    out = tmp_path / "mypart.toml"
    res = invoke(
        "tasks", "new", out, "--held", folder / "square_peg.stl",
        "--fixed", folder / "plate_3holes.stl", "--units", "mm",
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    data = tomllib.loads(out.read_text())
    assert data["fixed"]["hole_pos"] == [0.0, 0.0, 15.0]  # the 10.2 mm hole: least clearance
    assert data["units"] == "mm" and data["task"] == "mesh"
    png = tmp_path / "cell.png"
    res = invoke("tasks", "show", out, "--plot", png, "--no-checks")
    assert res.exit_code == 0, res.output
    assert "0.100 mm" in res.output and "11 (boxes" in res.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


def test_show_runs_the_cell_checks(mesh_examples) -> None:
    res = invoke("tasks", "show", mesh_examples["usb"])
    assert res.exit_code == 0, res.output
    assert res.output.count("pass ") == 3 and "FAIL" not in res.output


def test_bad_input_is_one_line_and_exit_2(mesh_examples, tmp_path: Path) -> None:
    folder = Path(mesh_examples["square-peg"]).parent
    cases = [
        (("--held", tmp_path / "nope.stl", "--fixed", folder / "plate_3holes.stl"), "not exist"),
        (("--held", folder / "square_peg.stl", "--fixed", folder / "plate_3holes.stl"), "units"),
    ]
    for args, words in cases:
        out = tmp_path / "bad.toml"
        res = invoke("tasks", "new", out, *args)
        assert res.exit_code == 2, res.output
        assert words in res.output and "Traceback" not in res.output
        assert not out.exists()  # nothing half-written
    res = invoke("tasks", "example", "nope", tmp_path)
    assert res.exit_code == 2 and "examples" in res.output
    res = invoke("bench", "search", "--task", tmp_path / "nope.toml", "--demo", tmp_path / "d.h5")
    assert res.exit_code == 2 and "nope.toml" in res.output
