"""Set-ups drawn from a task's error distribution: training and held-out streams."""

import numpy as np
import pytest

from teachfit.core.errors import SkillError
from teachfit.core.params import LearningError
from teachfit.execution.setups import draw_setups
from teachfit.execution.skill_trial import peg_in_hole_setup
from teachfit.learning.objective import SkillObjective
from teachfit.tasks.registry import get_task


def _same_pose(a, b):
    return np.allclose(a.pos, b.pos) and np.allclose(a.quat, b.quat)


def test_one_training_setup_is_the_seeds_own_setup():
    task = get_task("peg2d")
    one = peg_in_hole_setup(task, 3, 2)
    drawn = draw_setups(task, 3, 2)
    assert drawn.setups == 1 and drawn.of_start == (0, 0)
    assert all(_same_pose(a, b) for a, b in zip(drawn.setup.starts, one.starts, strict=True))
    assert _same_pose(drawn.taught2world[0], one.task2world)


def test_setups_join_their_starts_each_in_its_own_taught_frame():
    task = get_task("peg")
    drawn = draw_setups(task, 0, 2, setups=3)
    s = drawn.setup
    assert len(s.starts) == 6 and drawn.of_start == (0, 0, 1, 1, 2, 2)
    # each start runs in the frame its own set-up gives it (peg: the taught hole moved by the
    # task's deliberate start deviation); the three taught holes differ
    for i, k in enumerate(drawn.of_start):
        own = peg_in_hole_setup(task, (0, 0, k), 2)
        assert _same_pose(s.frame(i), own.frame(i % 2))
        assert _same_pose(drawn.taught2world[k], own.task2world)
    xy = np.array([t.pos[:2] for t in drawn.taught2world])
    assert len({tuple(np.round(p, 9)) for p in xy}) == 3
    # the taught-pose error is the task's: a fraction of a millimetre, not zero
    off = [float(np.hypot(*e.pos[:2])) for e in drawn.taught_errors()]
    assert all(0 < d < 5 * task.params.hole_pos_sigma * 3 for d in off)
    # reproducible from the seed
    again = draw_setups(task, 0, 2, setups=3)
    assert all(
        _same_pose(a, b) for a, b in zip(again.taught2world, drawn.taught2world, strict=True)
    )


def test_held_out_setups_are_never_training_setups():
    task = get_task("peg2d")
    train = draw_setups(task, 0, 1, setups=8).taught2world
    train += (draw_setups(task, 0, 1).taught2world[0],)
    held = draw_setups(task, 0, 1, setups=8, held_out=True).taught2world
    for h in held:
        assert not any(_same_pose(h, t) for t in train)


def test_per_setup_success_needs_every_start():
    drawn = draw_setups(get_task("peg2d"), 0, 2, setups=3)
    assert drawn.per_setup([True, True, True, False, False, False]) == [True, False, False]
    # a set-up counts once all its executions finished: set-up 1 half finished is left out
    assert drawn.per_setup([True, True, True]) == [True]


def test_bad_setup_counts_are_refused():
    with pytest.raises(SkillError, match="--setups must be >= 1"):
        draw_setups(get_task("peg2d"), 0, 2, setups=0)
    with pytest.raises(LearningError, match="--setups must be >= 1"):
        SkillObjective("peg2d", setups=0)


def test_objective_evaluates_every_setup_and_stores_the_count():
    one = SkillObjective("peg2d", n_starts=1)
    three = SkillObjective("peg2d", n_starts=1, setups=3)
    assert "setups" not in one.context()  # a study stored before the option still resumes
    assert three.context()["setups"] == 3
    out = three.outcome(None)
    assert len(out.traces) == 3 and len(out.costs) == 3
    assert three.trial().setup.frames  # each execution in its own set-up's frame
