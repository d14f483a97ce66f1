"""Built-in skills by name, and loading a skill from a name or a TOML file."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from teachfit.core.errors import ModelError, SkillError
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills import peg_in_hole
from teachfit.skills.follow import FollowConfig, follow_skill
from teachfit.skills.graph import Skill
from teachfit.skills.loader import load_skill
from teachfit.skills.tilt import TiltConfig


def tilted_search(controller: str = "adaptive") -> Skill:
    """The graph every tilted search of a sharp-edged hole runs (``execution.search``,
    the teacher's tilted hand), here for a 40 mm pass along +x in 8 s with every phase
    (an ``off_depth``): for showing it. ``controller`` is not used."""
    t = np.array([0.0, 8.0])
    pos = np.array([[-0.02, 0.0, 0.0], [0.02, 0.0, 0.0]])
    pass_ = SetpointTrajectory.from_path(t, pos, name="tilted-search")
    skill = follow_skill(pass_, FollowConfig(tilt=TiltConfig(off_depth=0.01)))
    return replace(
        skill,
        doc="a search with the part tilted: feel the drop, slide to the wall, turn upright; "
        "lifted back when it fell off the top (skills/tilt.py)",
    )


#: name -> builder taking the controller kind ("adaptive" adds its meta-parameters)
SKILLS: dict[str, Callable[[str], Skill]] = {
    peg_in_hole.NAME: peg_in_hole.build,
    "tilted-search": tilted_search,
}


def get_skill(spec: str, controller: str = "adaptive") -> Skill:
    """A built-in skill by name, one loaded from a ``.toml`` file, or the joined skill
    ``peg-in-hole+search:MODEL`` with the search model file ``MODEL`` as its recovery."""
    joined = "peg-in-hole+search:"
    if spec.startswith(joined):
        # imported here: the search model pulls in scikit-learn, which plain skills never need
        from teachfit.models.search_model import SearchModel
        from teachfit.skills import peg_in_hole_search

        try:
            model = SearchModel.load(spec[len(joined) :])
        except ModelError as exc:
            raise SkillError(f"{exc} (the skill {spec!r} needs a search model file)") from exc
        return peg_in_hole_search.build(model, controller)
    if spec in SKILLS:
        return SKILLS[spec](controller)
    if spec.endswith(".toml"):
        if not Path(spec).exists():
            raise SkillError(f"skill file {spec} does not exist")
        return load_skill(spec)
    raise SkillError(
        f"unknown skill {spec!r}; built-in skills: {sorted(SKILLS)}, a .toml file, or "
        f"{joined}MODEL (a search model file)"
    )
