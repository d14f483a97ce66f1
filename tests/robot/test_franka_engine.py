"""The execution engine drives the Franka through the real protocol like any other robot."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")

from teachfit.core.control import AdaptiveSpec  # noqa: E402
from teachfit.core.outcome import Outcome  # noqa: E402
from teachfit.core.setpoints import SetpointTrajectory  # noqa: E402
from teachfit.execution.follow import run_trajectory  # noqa: E402
from teachfit.robot.registry import make_robot  # noqa: E402
from teachfit.skills.follow import FollowConfig  # noqa: E402
from teachfit.tasks import get_task  # noqa: E402


def test_a_search_trajectory_runs_on_the_franka_through_the_engine(franka_sim: object) -> None:
    """A 1 s, 15 mm set-point line 2 cm above the (absent: franky-sim has no cell) block, run by
    the same engine as every simulated search, with the adaptive law as data: it follows the
    line, logs every command period, and ends by the time budget (nothing to insert into)."""
    task = get_task("peg2d")
    robot = make_robot("franka", task, host="127.0.0.1", realtime=False)
    try:
        start = task.contact_pose([0.0, 0.0]).translated([0, 0, 0.02])
        t = np.linspace(0.0, 1.0, 21)
        pos = start.pos + np.outer(t, [0.015, 0.0, 0.0])
        line = SetpointTrajectory.from_path(t, pos, np.tile(start.quat, (t.size, 1)))
        cfg = FollowConfig(push_force=0.0, settle_time=0.5, stiffness_along=2500.0,
                           stiffness_across=2500.0, stiffness_z=2500.0)  # fmt: skip
        res = run_trajectory(robot, task, line, start, cfg, controller=AdaptiveSpec())
    finally:
        robot.close()
    assert res.outcome is Outcome.TIMEOUT and res.detected is False
    assert res.log.n_samples >= 100  # ~100 Hz over the 1.5 s budget (a real loop jitters)
    assert np.all(np.diff(res.log.t) > 0)
    moved = res.log.pos[-1] - res.log.pos[0]
    assert 0.008 < moved[0] < 0.02 and abs(moved[1]) < 0.004  # joint friction: mm short


def test_a_skill_trial_runs_on_the_franka(franka_sim: object) -> None:
    """Johannsmeier et al.'s peg-in-hole skill with the adaptive law, as a learning trial would run
    it, on the Franka through the protocol. franky-sim has no cell: the skill descends through its
    approach into free space, and what ends it depends on the real loop's timing (its time
    limit or error exit, or its depth condition once the part is below the entry height, which
    a pose-based detector cannot tell from an insertion without the cell)."""
    from teachfit.execution.skill_trial import SkillTrial, peg_in_hole_setup

    task = get_task("peg2d")
    setup = peg_in_hole_setup(task, seed=0, n_starts=1, controller="adaptive")
    trial = SkillTrial(setup, "adaptive", robot="franka", host="127.0.0.1", realtime=False)
    try:
        out = trial()
    finally:
        trial.robot.close()
    (res,) = out.traces
    assert res.visits[0].node == "approach"
    assert res.outcome in (Outcome.SUCCESS, Outcome.TIMEOUT, Outcome.ERROR_CONDITION)
    assert res.log.n_samples > 10 and len(out.successes) == 1
    depth = res.log.pos[0, 2] - res.log.pos[:, 2].min()
    assert depth > 0.005  # it moved down towards the (absent) hole under the skill's command
