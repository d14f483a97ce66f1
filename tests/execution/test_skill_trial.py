from __future__ import annotations

import pytest

from teachfit.core.errors import SkillError
from teachfit.execution import peg_in_hole_setup
from teachfit.learning.objective import SkillObjective
from teachfit.tasks import get_task


@pytest.mark.parametrize(("name", "high"), [("key", 0.0003 / 0.009), ("puzzle", 0.0004 / 0.03)])
def test_the_set_up_searches_the_task_s_own_rotational_amplitude(name: str, high: float) -> None:
    setup = peg_in_hole_setup(get_task(name), seed=0)
    assert setup.skill.space.domains["a_r"].high == pytest.approx(high)
    assert setup.skill.space.domains["force"].high == 20.0  # the skill's own domain
    wide = SkillObjective(name, task_overrides=(("a_r_max", 0.1),))
    assert wide.space.domains["a_r"].high == 0.1


def test_a_round_peg_keeps_the_skill_s_rotational_amplitude() -> None:
    setup = peg_in_hole_setup(get_task("peg"), seed=0)
    assert setup.skill.space.domains["a_r"].high == 0.1


def test_a_value_beyond_the_task_s_bound_names_the_task() -> None:
    setup = peg_in_hole_setup(get_task("key"), seed=0)
    with pytest.raises(SkillError, match=r"task key bounds it: a task parameter widens it"):
        setup.skill.resolve({"a_r": 0.05})
    setup.skill.resolve({"a_r": 0.03})  # inside the bound
