"""The scripted hand (``demo record --hand``): a guide's push inside the Franka twin's physics,
seen in the recording's motion and wrench; bad guides refused in one line."""

from __future__ import annotations

import socket
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.core.errors import TeachfitError
from teachfit.robot.franka import hand_channel
from teachfit.robot.franka.hand import (
    Guide,
    GuideError,
    HandParams,
    parse_guide,
    read_guide,
    sweep_guide,
)

GOOD = "t,x,y,press\n0,0,0,0\n1,0.01,0,2\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("time,x,y,f\n0,0,0,0\n1,0,0,0\n", "the first line must be t,x,y,press"),
        ("t,x,y,press\n0,0,0,0\n", "needs 2 to"),
        ("t,x,y,press\n0,0,0,0\n1,0,zero,0\n", "line 3: needs 4 numbers"),
        ("t,x,y,press\n0,0,0,0\n1,0,0\n", "line 3: needs 4 numbers"),
        ("t,x,y,press\n0,0,0,0\n0,0,0,0\n", "t must increase strictly"),
        ("t,x,y,press\n0,0,0,0\n1,0,nan,0\n", "not a finite number"),
        ("t,x,y,press\n-2,0,0,0\n-1,0,0,0\n", "t must end after 0 s"),
        ("t,x,y,press\n0,0,0,0\n1,0.5,0,0\n", "within 0.1 m of the hole"),
        ("t,x,y,press\n0,0,0,0\n1,0,0,-31\n", "press must be within +-30 N"),
    ],
)
def test_a_bad_guide_is_refused_naming_it_and_the_fix(text: str, message: str) -> None:
    with pytest.raises(GuideError) as err:
        parse_guide(text, "--hand g.csv")
    assert str(err.value).startswith("--hand g.csv") and message in str(err.value)
    assert "header t,x,y,press" in str(err.value)  # the fix


def test_the_guide_interpolates_its_target_and_lets_go_after_its_end() -> None:
    guide = parse_guide("t,x,y,press\n-1,0,0,0\n0,0,0,2\n2,0.02,-0.01,4\n", "g")
    assert guide.lead_in == 1.0 and guide.end == 2.0
    now = guide.at(1.0)
    assert now is not None
    np.testing.assert_allclose(now[0], [0.01, -0.005])
    np.testing.assert_allclose(now[1], [0.01, -0.005])  # m/s along the segment
    assert now[2] == pytest.approx(3.0)
    assert guide.at(2.01) is None


def test_the_sweep_guide_starts_there_ends_over_the_hole_and_reads_back(tmp_path: Path) -> None:
    guide = sweep_guide(start=(-0.024, 0.018), seed=3)
    path = tmp_path / "guide.csv"
    path.write_text(guide.to_csv())
    back = read_guide(path)
    recorded = back.xy[back.t >= 0]
    assert np.linalg.norm(recorded[0] - [-0.024, 0.018]) < 2e-3
    np.testing.assert_allclose(recorded[-1], [0.0, 0.0], atol=1e-9)
    assert back.press[-1] == 6.0 and back.lead_in == 7.0 and back.press[0] < 0  # lifts first
    # the passes sweep 15 mm either side of the line from the start to the hole
    u = np.array([0.024, -0.018]) / 0.03
    across = (recorded + [0.024, -0.018]) @ np.array([-u[1], u[0]])
    assert across.max() > 0.014 and across.min() < -0.014


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_the_channel_hands_a_guide_over_and_refuses_junk(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(hand_channel, "HAND_PORT", _free_port())
    taken: list[Guide] = []
    with hand_channel.HandChannel("127.0.0.1", taken.append):
        hand_channel.send_guide("127.0.0.1", parse_guide(GOOD, "g"))
        with socket.create_connection(("127.0.0.1", hand_channel.HAND_PORT)) as conn:
            conn.sendall(b"hello\nEND\n")
            assert conn.makefile().readline().startswith("ERROR not a guide")
    assert len(taken) == 1
    np.testing.assert_allclose(taken[0].xy[-1], [0.01, 0.0])


def test_send_guide_to_no_twin_says_a_scripted_hand_guides_only_the_twin(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(hand_channel, "HAND_PORT", _free_port())
    with pytest.raises(TeachfitError, match="^--hand g.csv: nothing answers.*guides only the twin"):
        hand_channel.send_guide("127.0.0.1", parse_guide(GOOD, "g"), "--hand g.csv")


@pytest.mark.parametrize(
    ("content", "extra", "message"),
    [
        ("t,x,y\n0,0,0\n", [], "the first line must be t,x,y,press"),
        (None, [], "cannot read it"),
        (GOOD, ["--robot", "floating"], "guides the Franka twin only"),
        (GOOD, ["--host", "10.1.2.3"], "is not loopback"),
        (GOOD, ["--duration", "3"], "drop --duration"),
    ],
)
def test_demo_record_refuses_a_bad_hand_in_one_line_before_connecting(
    tmp_path: Path, content: str | None, extra: list[str], message: str
) -> None:
    guide = tmp_path / "guide.csv"
    if content is not None:
        guide.write_text(content)
    out = tmp_path / "demos.h5"
    args = ["demo", "record", "--task", "peg2d", "--robot", "franka", "--host", "127.0.0.1"]
    args += ["--no-realtime", "--hand", str(guide), "--out", str(out), *extra]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and message in lines[0] and "guide.csv" in lines[0], res.output
    assert not out.exists()


def test_a_scripted_push_moves_the_arm_and_reads_in_the_recorded_wrench(
    franka_twin: Any,
) -> None:
    """The twin of ``peg`` (TCP 5 cm over the hole, free air): idle 0.2 s, then the hand pulls
    the TCP towards x = +1 cm and presses 3 N down for 0.3 s, then lets go."""
    pytest.importorskip("pylibfranka")
    from teachfit.demonstrations.kinesthetic import record_demonstration
    from teachfit.robot.franka import franka_for_task
    from teachfit.tasks import get_task

    franka_twin()
    guide = parse_guide(
        "t,x,y,press\n0,0,0,0\n0.2,0,0,0\n0.21,0.01,0,3\n0.5,0.01,0,3\n0.51,0.01,0,0\n0.7,0.01,0,0\n",
        "g",
    )
    arm = franka_for_task(get_task("peg"), host="127.0.0.1", realtime=False)
    try:
        sent = (guide, lambda g: hand_channel.send_guide("127.0.0.1", g), "push.csv")
        demo = record_demonstration(arm, "peg", hand=sent)
    finally:
        arm.close()
    t, w, x = demo.t, demo.wrench, demo.pos[:, 0] - get_task("peg").hole2world.pos[0]
    assert demo.meta["hand"] == "push.csv" and t[-1] == pytest.approx(0.7, abs=0.02)
    before, pushed = t < 0.18, (t > 0.35) & (t < 0.5)  # past the estimate's filter lag
    assert np.abs(w[before, :3]).max() < 0.2  # nobody touches it yet (the reset tared)
    # environment on the tool (libfranka reads the opposite): the press -z, and across the
    # hand's spring-damper pull towards x = 1 cm, from the recorded motion
    hand = HandParams()
    press = -3.0 - hand.press_damping * np.gradient(demo.pos[:, 2], t)
    np.testing.assert_allclose(w[pushed, 2], press[pushed], atol=0.4)
    assert w[pushed, 2].max() < -1.0
    pull = hand.stiffness * (0.01 - x) - hand.damping * np.gradient(x, t)
    pull = np.clip(pull, -hand.max_force, hand.max_force)
    np.testing.assert_allclose(w[pushed, 0], pull[pushed], atol=0.4)
    assert w[pushed, 0].min() > 0.5
    assert x[-1] - x[0] > 0.008 and demo.pos[-1, 2] - demo.pos[0, 2] < -0.01  # it gave way


def test_the_example_guide_reads() -> None:
    guide = read_guide(Path(__file__).parents[2] / "examples" / "guide_peg2d.csv")
    assert guide.lead_in > 0 and guide.end > 10.0
    np.testing.assert_allclose(guide.xy[-1], [0.0, 0.0])  # it ends over the hole
