"""Skill graphs (Johannsmeier et al. 2019): manipulation primitives, conditions, parameters;
following set-point trajectories (search, replay) as a primitive. They run in
:mod:`teachfit.execution.engine`."""

from teachfit.skills.follow import FollowConfig, FollowSetpoints, follow_skill
from teachfit.skills.graph import Node, Skill, Transition
from teachfit.skills.library import SKILLS, get_skill
from teachfit.skills.loader import load_skill, skill_to_toml
from teachfit.skills.params import (
    ContextParam,
    LearnedParam,
    SkillParams,
    read_params_toml,
    write_params_toml,
)
from teachfit.skills.tilt import TiltConfig

__all__ = [
    "SKILLS",
    "ContextParam",
    "FollowConfig",
    "FollowSetpoints",
    "LearnedParam",
    "Node",
    "Skill",
    "SkillParams",
    "TiltConfig",
    "Transition",
    "follow_skill",
    "get_skill",
    "load_skill",
    "read_params_toml",
    "write_params_toml",
    "skill_to_toml",
]
