"""Watching the grasp over libfranka's gripper protocol (franky-sim's Franka Hand)."""

from __future__ import annotations

import pytest

from teachfit.robot.franka.grasp import PartLost

pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")


def test_a_part_released_from_the_fingers_is_lost_at_the_next_check(franka_sim: object) -> None:
    import pylibfranka as pf

    from teachfit.robot.franka.grasp import connect_gripper

    watch, why = connect_gripper(pf, "127.0.0.1")
    assert watch is not None and why == ""
    hand = watch.gripper  # a hand serves one client: commands go through the same connection
    width = hand.read_once().width
    # "grasp" at the width the fingers are at (the simulated hand holds no object): grasped
    assert hand.grasp(width, 0.05, 20.0, 0.005, 0.005)
    watch.check()  # the reference: the part held when the run began
    assert watch.active and watch.reference == pytest.approx(width, abs=1e-3)
    watch.check()  # unchanged: nothing raised
    hand.move(min(width + 0.03, hand.read_once().max_width), 0.1)  # the fingers open
    with pytest.raises(PartLost, match="the part is no longer in the gripper"):
        watch.check()


def test_a_hand_holding_nothing_at_the_start_is_not_watched(franka_sim: object) -> None:
    import pylibfranka as pf

    from teachfit.robot.franka.grasp import connect_gripper

    watch, _ = connect_gripper(pf, "127.0.0.1")
    assert watch is not None
    hand = watch.gripper
    hand.move(hand.read_once().max_width, 0.1)  # open: nothing grasped
    watch.check()
    assert not watch.active and "the grasp is not watched" in watch.note
    watch.check()  # off: never raises
