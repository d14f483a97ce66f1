"""``teachfit tasks new`` accepts a round peg at 0.2 mm diametral clearance (issue 32)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.tasks.mesh.examples import write_example


def test_new_accepts_a_round_peg_in_a_bore_0_2_mm_wider(tmp_path: Path) -> None:
    folder = write_example("round-peg", tmp_path / "parts").parent
    out = tmp_path / "peg8.toml"
    args = [
        "tasks", "new", out, "--held", folder / "round_peg.stl",
        "--fixed", folder / "plate_2bores.stl", "--units", "mm",
    ]  # fmt: skip
    res = CliRunner().invoke(app, [str(a) for a in args])
    assert res.exit_code == 0, res.output
    assert "0.100 mm after decomposition (100 % kept)" in res.output
    assert tomllib.loads(out.read_text())["fixed"]["hole_pos"] == [-12.0, 0.0, 9.0]  # 8.2 mm
