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


def test_a_reflex_is_recovered_and_its_execution_run_once_more() -> None:
    """A safety reflex mid-execution (injected on the simulated arm's 200th tick, once) ends
    that execution as a robot fault; the trial resets and runs it again, and says so."""
    from teachfit.core.errors import ReflexFault
    from teachfit.core.outcome import Outcome
    from teachfit.execution.skill_trial import SkillTrial

    trial = SkillTrial(peg_in_hole_setup(get_task("peg2d"), seed=0, n_starts=2))
    robot, step = trial.robot, trial.robot.step
    ticks = [0]

    def step_with_one_reflex(n: int = 1) -> object:
        ticks[0] += n
        if ticks[0] >= 200 and ticks[0] - n < 200:
            raise ReflexFault("cartesian_reflex: contact force above its threshold")
        return step(n)

    robot.step = step_with_one_reflex
    out = trial()
    assert out.retries == 1 and len(out.traces) == 2
    assert all(t.outcome is not Outcome.FAULT and not t.reflex for t in out.traces)
    # the same execution without the retry is the reflex the engine recorded
    ticks[0] = 0
    first = trial.run(None, trial.setup.starts[0])
    assert first.reflex and first.outcome is Outcome.FAULT and "cartesian_reflex" in first.reason


def test_a_skill_without_a_context_parameter_the_task_gives_still_sets_up(tmp_path) -> None:
    """A mesh task's fit gives context parameters (``pass_end``, ``k_across``, ...) that a skill
    written without them (a user's older skill file; here the built-in tilted search) does not
    declare: the skill sets up on the task and takes the context it has."""
    from teachfit.skills.library import get_skill
    from teachfit.tasks.mesh.examples import write_example
    from teachfit.tasks.registry import load_task

    write_example("round-peg", tmp_path)
    task = load_task(str(tmp_path / "round-peg.toml"))
    old = get_skill("tilted-search", "adaptive")
    assert "pass_end" not in old.params.context
    setup = peg_in_hole_setup(task, seed=0, n_starts=1, skill=old)
    assert setup.skill.params.context == old.params.context  # none it does not declare


def test_a_trial_reads_the_same_noise_whatever_the_worker_ran_before() -> None:
    """The noise restarts from the trial's own values: a study's trial does not depend on
    which trials its worker evaluated first; other values read other noise."""
    import numpy as np

    from teachfit.execution.skill_trial import SkillTrial

    trial = SkillTrial(peg_in_hole_setup(get_task("peg2d"), seed=0, n_starts=1))
    values = {"force": 6.0}
    first = trial(values).traces[0].log.wrench
    trial({"force": 9.0})  # another trial in between draws noise of its own
    np.testing.assert_array_equal(trial(values).traces[0].log.wrench, first)
    assert trial.noise_seed(values) != trial.noise_seed({"force": 6.5})
