"""Built-in skills by name, and loading a skill from a name or a TOML file."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from teachfit.core.errors import SkillError
from teachfit.skills import peg_in_hole
from teachfit.skills.graph import Skill
from teachfit.skills.loader import load_skill

#: name -> builder taking the controller kind ("adaptive" adds its meta-parameters)
SKILLS: dict[str, Callable[[str], Skill]] = {peg_in_hole.NAME: peg_in_hole.build}


def get_skill(spec: str, controller: str = "adaptive") -> Skill:
    """A built-in skill by name, or one loaded from a ``.toml`` file."""
    if spec in SKILLS:
        return SKILLS[spec](controller)
    if spec.endswith(".toml"):
        if not Path(spec).exists():
            raise SkillError(f"skill file {spec} does not exist")
        return load_skill(spec)
    raise SkillError(f"unknown skill {spec!r}; built-in skills: {sorted(SKILLS)} (or a .toml file)")
