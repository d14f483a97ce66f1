"""The peg-in-hole skill on the torque-controlled FR3 arm with its default parameters."""

from teachfit.core.outcome import Outcome
from teachfit.execution.skill_trial import SkillTrial, peg_in_hole_setup
from teachfit.tasks import get_task


def test_default_skill_inserts_on_the_arm_after_a_real_lateral_move():
    # the arm lands with ~15 N (its apparent mass), whose friction alone once marked the lateral
    # move constrained at its first tick; with friction in the joints the soft align and insert
    # then never made up the skipped 3 mm and pressed beside the hole up to the force limit
    setup = peg_in_hole_setup(get_task("peg2d"), seed=0, n_starts=1)
    trial = SkillTrial(setup, robot="fr3", seed=0)
    out = trial()
    (run,) = out.traces
    assert run.outcome is Outcome.SUCCESS and out.successes == (True,)
    lateral = next(v for v in run.visits if v.node == "lateral")
    assert lateral.t_exit - lateral.t_enter > setup.skill.params.context["t_settle"].value
