"""Skill graphs (seed B): manipulation primitives, conditions, parameters, execution, metric.

A learner's view::

    from teachfit.skills import SkillTrial, peg_in_hole_setup
    setup = peg_in_hole_setup(task, seed=0, n_starts=4, controller="adaptive")
    trial = SkillTrial(setup, controller="adaptive")
    space = setup.skill.space                 # ParamSpace of the learned parameters
    outcome = trial(space.from_unit(u))       # 4 executions -> successes, costs, mean cost
    result = outcome.as_result()              # TrialResult for teachfit.learning
"""

from teachfit.skills.executor import ExecConfig, ExecutionTrace, NodeVisit, execute
from teachfit.skills.graph import Node, Skill, Transition
from teachfit.skills.library import SKILLS, get_skill
from teachfit.skills.loader import load_skill, skill_to_toml
from teachfit.skills.metric import LearningMetric
from teachfit.skills.params import (
    ContextParam,
    LearnedParam,
    SkillParams,
    read_params_toml,
    write_params_toml,
)
from teachfit.skills.trial import SkillSetup, SkillTrial, TrialOutcome, peg_in_hole_setup

__all__ = [
    "SKILLS",
    "ContextParam",
    "ExecConfig",
    "ExecutionTrace",
    "LearnedParam",
    "LearningMetric",
    "Node",
    "NodeVisit",
    "Skill",
    "SkillParams",
    "SkillSetup",
    "SkillTrial",
    "Transition",
    "TrialOutcome",
    "execute",
    "get_skill",
    "load_skill",
    "peg_in_hole_setup",
    "read_params_toml",
    "write_params_toml",
    "skill_to_toml",
]
