"""The collision thresholds the Franka driver sets on connect (robot/franka/reflex.py)."""

from __future__ import annotations

import numpy as np
import pytest

from teachfit.core.errors import ControlError
from teachfit.robot.franka.reflex import (
    LIBFRANKA_CARTESIAN,
    LIBFRANKA_JOINT,
    REFLEX_MARGIN,
    reflex_thresholds,
)
from teachfit.robot.franka.safety import FrankaLimits

#: a TCP Jacobian (6, 7): levers of 0.5 m at the first joints, 0.1 m at the wrist
JAC = np.vstack([np.full((3, 7), 0.5 / np.sqrt(3)), np.full((3, 7), 1 / np.sqrt(3))])
JAC[:3, 4:] = 0.1 / np.sqrt(3)


class _Robot:
    def __init__(self) -> None:
        self.calls: list[tuple[list[float], ...]] = []

    def set_collision_behavior(self, *args: list[float]) -> None:
        self.calls.append(args)


def test_default_thresholds_sit_a_margin_above_what_the_law_may_command() -> None:
    lim = FrankaLimits()
    th = reflex_thresholds(lim, JAC, k_lever=0.06)
    force = REFLEX_MARGIN * lim.max_force
    assert th.upper_force[:3] == (force,) * 3 == (75.0,) * 3
    # the torque at K: the margin over max_torque plus the TCP force's moment 0.06 m away
    np.testing.assert_allclose(th.upper_force[3:], REFLEX_MARGIN * lim.max_torque + force * 0.06)
    # joints: the TCP wrench's torque (75 N at 0.5 m + 7.5 N·m = 45 N·m), capped at the limits
    np.testing.assert_allclose(th.upper_torque[:4], 45.0)
    assert th.upper_torque[4:] == (12.0,) * 3  # over the 12 N·m the wrist joints can give
    assert th.lower_force == LIBFRANKA_CARTESIAN[:3] + (12.0,) * 3  # contact: libfranka's
    assert th.lower_torque == LIBFRANKA_JOINT[:4] + (12.0,) * 3


def test_a_low_reflex_force_lowers_the_cartesian_thresholds_not_the_joints_below_libfrankas() -> (
    None
):
    th = reflex_thresholds(FrankaLimits(), JAC, k_lever=0.0, reflex_force=8.0)
    assert th.upper_force[:3] == (8.0,) * 3
    assert th.lower_force[:3] == (8.0,) * 3  # the contact level never above the collision one
    assert all(u >= d for u, d in zip(th.upper_torque[:4], LIBFRANKA_JOINT, strict=False))


def test_send_passes_the_four_arrays_to_set_collision_behavior() -> None:
    th = reflex_thresholds(FrankaLimits(), JAC, k_lever=0.06, reflex_force=30.0)
    robot = _Robot()
    th.send(robot)
    (call,) = robot.calls
    assert [len(a) for a in call] == [7, 7, 6, 6]
    assert call[3][:3] == [30.0] * 3


@pytest.mark.parametrize("bad", [0.0, -5.0, float("nan"), float("inf")])
def test_a_reflex_force_that_is_not_a_positive_number_is_refused(bad: float) -> None:
    with pytest.raises(ControlError, match=r"reflex_force .*a number > 0"):
        reflex_thresholds(FrankaLimits(), JAC, 0.0, reflex_force=bad)


def test_the_driver_params_refuse_a_bad_reflex_force_before_connecting() -> None:
    from teachfit.robot.franka.driver import FrankaParams

    assert FrankaParams(reflex_force=40.0).reflex_force == 40.0
    with pytest.raises(ControlError, match="reflex_force -1"):
        FrankaParams(reflex_force=-1.0)


@pytest.mark.parametrize(
    ("command", "value", "host", "said"),
    [
        (["skill", "run", "--task", "peg"], "20", None, "--reflex-force sets a real robot's"),
        (["skill", "run", "--task", "peg"], "0", "127.0.0.1", "--reflex-force 0: give"),
        (["skill", "run", "--task", "peg"], "-3", "127.0.0.1", "--reflex-force -3: give"),
        (["learn", "skill", "--task", "peg"], "nan", "127.0.0.1", "--reflex-force nan: give"),
        (["assemble", "--task", "peg2d"], "inf", "127.0.0.1", "--reflex-force inf: give"),
    ],
)
def test_cli_refuses_a_bad_reflex_force_in_one_line(
    tmp_path: object, command: list[str], value: str, host: str | None, said: str
) -> None:
    from typer.testing import CliRunner

    from teachfit.cli import app

    arm = ["--robot", "franka", "--host", host, "--no-realtime"] if host else []
    study = ["--study", f"{tmp_path}/s.db"] if command[0] == "learn" else []
    res = CliRunner().invoke(app, [*command, *arm, *study, "--reflex-force", value])
    assert res.exit_code == 2 and len(res.output.strip().splitlines()) == 1, res.output
    assert said in res.output, res.output
