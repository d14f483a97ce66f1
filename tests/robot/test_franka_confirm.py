"""``--confirm``: a person confirms each reset of a real arm on the terminal."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import Pose
from teachfit.robot.franka.confirm import ResetDeclined, terminal_confirm

GOAL = Pose(np.array([0.01, -0.02, 0.15]))


def test_enter_moves_and_q_stops() -> None:
    asked: list[str] = []

    def answer(text: str) -> str:
        asked.append(text)
        return ""

    terminal_confirm(answer, interactive=True)(GOAL)
    assert asked == ["reset to (10.0, -20.0, 150.0) mm: Enter moves the arm, q stops the run > "]
    with pytest.raises(ResetDeclined, match="declined at the --confirm prompt"):
        terminal_confirm(lambda _t: " q ", interactive=True)(GOAL)


def test_without_a_terminal_it_is_refused_before_anything() -> None:
    with pytest.raises(TeachfitError, match="stdin is not one"):
        terminal_confirm(interactive=False)


@pytest.mark.parametrize("host", [None, "127.0.0.1"])
def test_cli_refuses_confirm_without_a_host_or_a_terminal(host: str | None) -> None:
    if host is not None:
        pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")
    extra = ["--robot", "franka", "--host", host, "--no-realtime"] if host else []
    res = CliRunner().invoke(app, ["skill", "run", "--task", "peg", "--confirm", *extra])
    assert res.exit_code == 2 and len(res.output.strip().splitlines()) == 1, res.output
    assert ("give --host" if host is None else "stdin is not one") in res.output


def test_a_declined_reset_leaves_the_arm_where_it_was(franka_sim: object) -> None:
    from teachfit.robot.franka import FrankaFrames, ee2tcp_for_part
    from teachfit.robot.franka.driver import FrankaParams, FrankaRobot

    params = FrankaParams(frames=FrankaFrames(ee2tcp=ee2tcp_for_part(0.05)))
    seen: list[Pose] = []
    with FrankaRobot("127.0.0.1", params=params, realtime=False, confirm=seen.append) as robot:
        robot.reset(GOAL)
        assert seen == [GOAL]
        robot.confirm = terminal_confirm(lambda _t: "q", interactive=True)
        here = robot.step(1).pos
        with pytest.raises(ResetDeclined):
            robot.reset(Pose(GOAL.pos + [0.03, 0.0, 0.0]))
        assert np.linalg.norm(robot.step(20).pos - here) < 1e-3
