"""Execution: the one engine every skill, search, replay and teacher runs through.

A skill's view::

    from teachfit.execution import SkillTrial, peg_in_hole_setup
    setup = peg_in_hole_setup(task, seed=0, n_starts=4, controller="adaptive")
    trial = SkillTrial(setup, controller="adaptive", robot="floating")
    space = setup.skill.space                 # ParamSpace of the learned parameters
    outcome = trial(space.from_unit(u))       # 4 executions -> successes, costs, mean cost
"""

from teachfit.execution.batch import episode_rng, episode_seed, run_batch
from teachfit.execution.engine import ExecConfig, ExecutionResult, NodeVisit, execute
from teachfit.execution.follow import run_trajectory
from teachfit.execution.log import ExecutionLog
from teachfit.execution.metric import LearningMetric
from teachfit.execution.skill_trial import SkillSetup, SkillTrial, TrialOutcome, peg_in_hole_setup

__all__ = [
    "ExecConfig",
    "ExecutionLog",
    "ExecutionResult",
    "LearningMetric",
    "NodeVisit",
    "SkillSetup",
    "SkillTrial",
    "TrialOutcome",
    "episode_rng",
    "episode_seed",
    "execute",
    "peg_in_hole_setup",
    "run_batch",
    "run_trajectory",
]
