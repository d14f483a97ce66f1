"""``teachfit bench parts``: options checked first, a table row per method with an interval."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from teachfit.bench import parts as bp
from teachfit.cli import app
from teachfit.metrics.stats import summarize


def test_bench_parts_prints_a_row_per_method_with_its_interval(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Wiring only: the executions are replaced (the bench layer runs them for real below)."""
    seen = []

    def fake(part, task, robot, sizes, seed=0, methods=bp.METHODS, progress=None):  # noqa: ANN001, ANN202
        seen.append((part, Path(task).is_file(), robot, sizes))
        s = summarize([True, False], [1.5, 0.0])
        return [bp.PartRow(part, robot, m, s, ("error-condition: stuck",)) for m in methods]

    monkeypatch.setattr(bp, "bench_part", fake)
    md, png = tmp_path / "parts.md", tmp_path / "parts.png"
    args = [
        "bench", "parts", "--parts", "round8-sharp-through", "--robots", "floating",
        "--setups", "2", "--trials", "3", "--starts", "4", "--train-setups", "1",
        "--markdown", str(md), "--plot", str(png),
    ]  # fmt: skip
    res = CliRunner().invoke(app, args, env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    assert seen == [("round8-sharp-through", True, "floating", bp.Sizes(2, 3, 4, 1, workers=None))]
    text = md.read_text()
    head = next(line for line in text.splitlines() if line.startswith("| part"))
    assert head == "| part | robot | " + " | ".join(bp.METHODS) + " |"
    rows = [line for line in text.splitlines() if line.startswith("| round8")]
    assert rows == ["| round8-sharp-through | floating" + " | 1/2 [9, 91] ✗" * 4 + " |"]
    misses = [line for line in text.splitlines() if line.startswith("- round8")]
    assert misses[0] == (
        "- round8-sharp-through / floating / skill / 1/2 = 50 % [9, 91]: 1x error-condition: stuck"
    )
    assert len(misses) == 4
    assert "missed on round8-sharp-through/floating/skill" in res.output
    assert png.is_file()


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [("--parts", "hexagon", "--parts: choose from"), ("--robots", "ur5", "--robots: choose"),
     ("--methods", "tilt", "--methods: choose"), ("--plot", "x.nope", "unknown image format")],
)  # fmt: skip
def test_bad_options_fail_in_one_line_before_any_run(
    tmp_path: Path, option: str, value: str, message: str
) -> None:
    res = CliRunner().invoke(
        app, ["bench", "parts", option, str(tmp_path / value) if option == "--plot" else value]
    )
    assert res.exit_code == 2
    assert message in res.output and "Traceback" not in res.output


def test_tasks_suite_writes_the_chosen_parts_and_refuses_an_unknown_one(tmp_path: Path) -> None:
    res = CliRunner().invoke(
        app,
        ["tasks", "suite", str(tmp_path / "s"), "--parts", "round8-sharp-through",
         "--clearance", "0.029"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    names = sorted(p.name for p in (tmp_path / "s").iterdir())
    assert names == [
        "round8-sharp-through-peg.stl", "round8-sharp-through-plate.stl",
        "round8-sharp-through.toml",
    ]  # fmt: skip
    assert "H7/g6 5-29 um, simulated 0.029 mm" in res.output
    bad = CliRunner().invoke(app, ["tasks", "suite", str(tmp_path / "t"), "--parts", "hexagon"])
    assert bad.exit_code == 2 and "unknown suite part" in bad.output
    assert not (tmp_path / "t").exists()
