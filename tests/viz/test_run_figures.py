"""The run-log figure: pose, wrench, depth and active node over time."""

from __future__ import annotations

from pathlib import Path

from media_checks import read_png
from run_logs import real_run

from teachfit.execution.recording import RunLog
from teachfit.viz.run_figures import plot_run


def test_plot_run_draws_every_episode(tmp_path: Path) -> None:
    episodes, info = real_run()
    run = RunLog.of(episodes, info, tmp_path)
    read_png(plot_run(run, tmp_path / "figs" / "run.png"), min_px=400)
