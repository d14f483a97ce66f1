"""MuJoCo's viewer needs a display: without one, one clear line and exit status 2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.core.errors import RenderError
from teachfit.demonstrations.dataset import Demonstration, write_dataset
from teachfit.robot.viewer import has_display, require_display


def test_without_a_display_view_says_so_in_one_line(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    if has_display():  # macOS / Windows always have one
        pytest.skip("this platform always has a display")
    with pytest.raises(RenderError, match="no display"):
        require_display()
    t = np.linspace(0.0, 1.0, 20)
    pos = np.column_stack([t * 0.01, np.zeros_like(t), np.full_like(t, 0.02)])
    demo = Demonstration(
        t, pos, np.tile([1.0, 0, 0, 0], (20, 1)), None, task="peg2d", source="simulated-teacher"
    )
    demos = write_dataset(tmp_path / "d.h5", [demo])
    res = CliRunner().invoke(app, ["view", "--demo", f"{demos}:0"])
    assert res.exit_code == 2 and "Traceback" not in res.output
    assert res.output.count("\n") == 1 and "teachfit render" in res.output


def test_a_display_variable_counts(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("DISPLAY", ":0")
    assert has_display()
