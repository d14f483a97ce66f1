"""``teachfit robot list`` / ``robot check``: what the registry holds, clear errors."""

from __future__ import annotations

from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.robot.registry import ROBOTS

runner = CliRunner()


def test_list_names_every_registered_robot_and_its_kind() -> None:
    res = runner.invoke(app, ["robot", "list"], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    rows = {line.split("│")[1].strip(): line for line in res.output.splitlines() if "│" in line}
    for name, entry in ROBOTS.items():
        assert ("simulated" if entry.simulated else "real") in rows[name]
    assert "teachfit[franka]" in res.output  # markup-like text is printed as is


def test_check_needs_a_real_robot_and_its_address() -> None:
    res = runner.invoke(app, ["robot", "check", "--robot", "floating"])
    assert res.exit_code == 2 and "simulated" in res.output
    res = runner.invoke(app, ["bench", "robot", "--robot", "fr3"])  # where its tick is timed
    assert res.exit_code == 2 and "bench sim --robot fr3" in " ".join(res.output.split())
    res = runner.invoke(app, ["robot", "check"])
    assert res.exit_code == 2 and "--host" in res.output
    res = runner.invoke(app, ["bench", "robot", "--host", "127.0.0.1", "--seconds", "0"])
    assert res.exit_code == 2 and "--seconds" in res.output


def test_learning_on_a_real_robot_is_not_parallel(tmp_path) -> None:
    study = tmp_path / "s.db"
    args = ["learn", "skill", "--robot", "franka", "--ray", "local", "--study", str(study)]
    res = runner.invoke(app, [*args, "--trials", "1"])
    assert res.exit_code == 2 and "real franka" in res.output
    assert not study.exists()


def test_bench_robot_appends_its_figures_as_markdown(tmp_path, monkeypatch) -> None:
    from teachfit.robot.franka import check

    timing = check.LoopTiming(
        ticks=10_000, compute_p50=283e-6, compute_p99=485e-6, compute_max=702e-6,
        overruns=3, missed_packets=1, period=1e-3, wall_rate=809.0,
    )  # fmt: skip
    monkeypatch.setattr(check, "bench_loop", lambda *args, **kwargs: timing)
    out = tmp_path / "robot.md"
    res = runner.invoke(app, ["bench", "robot", "--host", "127.0.0.1", "--markdown", str(out)])
    assert res.exit_code == 0, res.output
    text = out.read_text(encoding="utf-8")
    assert text.startswith("<!-- teachfit-run source=command")
    assert "| 283 µs | 485 µs | 702 µs | 3 | 1 | 809 ticks/s |" in text
