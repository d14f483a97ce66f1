"""The peg-in-hole context a fit gives (skills/fit_context.py), and what built-in tasks keep."""

from __future__ import annotations

import math

import numpy as np
import pytest

from teachfit.core.errors import SkillError
from teachfit.core.params import ParamDomain
from teachfit.skills import peg_in_hole
from teachfit.skills.fit_context import NEVER, FitGeometry, fit_context
from teachfit.skills.tilt import rim_lead
from teachfit.tasks.registry import get_task

DEFAULTS = {n: p.value for n, p in peg_in_hole.CONTEXT.items()}
TILT = ParamDomain(0.0, 0.3)


def test_a_sharp_tight_part_starts_beyond_three_sigma_with_a_small_tilt_and_a_light_press() -> None:
    # the round-peg example: r = 4 mm, c = 0.1 mm, no chamfer, sigma = 0.5 mm
    values, domains = fit_context(FitGeometry(0.004, 1e-4, 0.0, 5e-4), DEFAULTS, 0.25, TILT)
    start = 0.004 + 0.0041 + 3 * 5e-4
    assert values["lateral_dir"] == -1.0
    assert values["lateral_offset"] == pytest.approx(-start)
    assert values["pass_y"] == pytest.approx(0.001) and values["pass_end"] == pytest.approx(0.0041)
    assert values["roi"] == pytest.approx(math.hypot(start, 0.001) + 0.001)
    assert values["k_across"] == 0.0
    assert values["f_lateral"] == NEVER
    assert values["f_lateral_rev"] == pytest.approx(2 * DEFAULTS["f_lateral"])
    assert values["wall_depth"] == 0.0 and values["wall_x"] == pytest.approx(1e-4 + 1.5e-3)
    assert values["f_push"] == pytest.approx(0.5 * DEFAULTS["f_push"])
    t_lateral = (start + 0.0041) / (DEFAULTS["v_lateral"] * 0.25)
    assert values["t_lateral"] == pytest.approx(t_lateral)
    extra = t_lateral - DEFAULTS["t_lateral"] + 2 * (t_lateral + 1.0)
    assert values["t_max"] == pytest.approx(DEFAULTS["t_max"] + extra)
    assert values["t_reach"] == pytest.approx(start / (DEFAULTS["v_lateral"] * 0.25))
    # the jam-free tilt is 0.22 rad; turned upright about the TCP the low rim rises <= 0.45 mm
    assert math.acos(0.004 / 0.0041) > math.asin(4.5e-4 / 0.004)
    assert domains["tilt"].high == pytest.approx(math.asin(4.5e-4 / 0.004))  # 0.11 rad
    # a sharp rim that leans too little dips too little off the pass's line
    assert domains["tilt"].low == pytest.approx(0.5 * domains["tilt"].high)
    # the joined skill's search of a sharp edge is tilted, retried at the jam-free tilt
    assert values["search_tilt"] == 0.25
    assert values["search_retry_tilt"] == pytest.approx(math.acos(0.004 / 0.0041))
    assert values["search_reach"] == pytest.approx(0.0082)
    assert values["search_lead"] == pytest.approx(rim_lead(0.25, 0.008))
    assert values["search_drop"] == pytest.approx(2.5e-4) and values["search_friction"] == 0.3


def test_a_chamfered_loose_part_keeps_the_press_and_the_skill_s_tilt_domain() -> None:
    values, domains = fit_context(FitGeometry(0.005, 5e-4, 5e-4, 2e-4), DEFAULTS, 0.25, TILT)
    assert values["f_push"] == DEFAULTS["f_push"]
    assert "search_tilt" not in values  # a chamfer catches an upright search
    assert values["lateral_offset"] == pytest.approx(-(0.005 + 0.0055 + 6e-4))
    assert math.acos(0.0045 / 0.0055) > 0.3  # the fit allows more than the skill's own,
    assert domains["tilt"].high == pytest.approx(math.asin(4.5e-4 / 0.005))  # the turn less
    _, wide_domains = fit_context(FitGeometry(0.001, 5e-4, 5e-4, 2e-4), DEFAULTS, 0.25, TILT)
    assert wide_domains["tilt"].high == 0.3  # a part 2 mm wide: the skill's own domain
    assert domains["tilt"].low == wide_domains["tilt"].low == TILT.low  # a chamfer: as low
    # a top that ends nearer: the start stays over it
    near, _ = fit_context(FitGeometry(0.005, 5e-4, 5e-4, 2e-4, 0.008), DEFAULTS, 0.25, TILT)
    assert near["lateral_offset"] == -0.008
    # a short move: t_lateral stays at its default
    short, _ = fit_context(FitGeometry(0.001, 5e-4, 0.0, 0.0), DEFAULTS, 0.25, TILT)
    assert short["t_lateral"] == DEFAULTS["t_lateral"]
    assert short["t_max"] == pytest.approx(DEFAULTS["t_max"] + 2 * (DEFAULTS["t_lateral"] + 1.0))


@pytest.mark.parametrize(
    "args", [(0.0, 1e-4, 0.0, 0.0), (0.004, -1e-4, 0.0, 0.0), (0.004, 0.0, 0.004, 0.0)]
)
def test_an_impossible_fit_is_an_error(args: tuple[float, float, float, float]) -> None:
    with pytest.raises(SkillError, match="fit:"):
        FitGeometry(*args)


@pytest.mark.parametrize("name", ["peg2d", "socket3d", "peg", "key", "puzzle"])
def test_built_in_tasks_keep_johannsmeier_s_context(name: str) -> None:
    ctx = peg_in_hole.hole_context(get_task(name), np.random.default_rng(0))
    assert "pass_end" not in ctx.values  # 1 m: no extra pass is ever taken
    for key in (
        "lateral_dir",
        "lateral_offset",
        "roi",
        "k_across",
        "wall_depth",
        "wall_x",
        "pass_y",
    ):
        assert key not in ctx.values
    assert "tilt" not in ctx.domains


def test_the_round_peg_example_gives_its_fit(mesh_examples: dict[str, str]) -> None:
    task = get_task(mesh_examples["round-peg"])
    assert task.part_half_width == pytest.approx(0.004)
    assert task.clearance == pytest.approx(1e-4, rel=0.01)
    assert task.tip_chamfer == 0.0
    ctx = peg_in_hole.hole_context(task, np.random.default_rng(0))
    assert ctx.values["lateral_dir"] == -1.0
    assert ctx.values["lateral_offset"] == pytest.approx(-(0.004 + 0.0041 + 0.0015), abs=1e-6)
    assert ctx.values["search_friction"] == pytest.approx(task.params.friction)


def test_a_fit_extends_the_skill_s_own_time_limit(mesh_examples: dict[str, str]) -> None:
    """The joined skill's t_max (time for a search) grows by the fit's extension as the plain
    skill's does: a fit must not cut a skill's budget to the plain skill's."""
    from teachfit.skills import peg_in_hole_search

    task = get_task(mesh_examples["round-peg"])
    plain = peg_in_hole.hole_context(task, np.random.default_rng(0))
    joined = dict(peg_in_hole.CONTEXT) | peg_in_hole_search.CONTEXT
    ctx = peg_in_hole.hole_context(task, np.random.default_rng(0), joined)
    t_lateral = plain.values["t_lateral"]  # the fit's, longer than either skill's default
    own = {n: p.value for n, p in peg_in_hole_search.CONTEXT.items()}
    assert ctx.values["t_lateral"] == pytest.approx(t_lateral) and t_lateral > own["t_lateral"]
    extra = t_lateral - own["t_lateral"] + 2 * (t_lateral + 1.0)
    assert ctx.values["t_max"] == pytest.approx(own["t_max"] + extra)
    assert ctx.values["t_max"] > plain.values["t_max"] + 10.0  # the search's time kept


def test_a_sharp_rectangle_goes_corner_first_and_a_chamfered_one_does_not() -> None:
    from teachfit.skills.fit_context import CORNER_K, CORNER_ROLL, CORNER_SLOPE

    # rect12x8-sharp-through: r = 6 mm along the move, w = 4 mm across, c = 0.1 mm
    rect = FitGeometry(0.006, 1e-4, 0.0, 5e-4, corner=0.004)
    values, domains = fit_context(rect, DEFAULTS, 0.25, TILT)
    plain, _ = fit_context(FitGeometry(0.006, 1e-4, 0.0, 5e-4), DEFAULTS, 0.25, TILT)
    start = -values["lateral_offset"]
    assert values["lateral_dir_y"] == -CORNER_SLOPE and values["lateral_dir"] == -1.0
    assert values["start_y"] == pytest.approx(CORNER_SLOPE * start)  # through the taught axis
    assert values["roll"] == CORNER_ROLL and values["k_across"] == CORNER_K
    assert values["roi"] > math.hypot(start, CORNER_SLOPE * start)  # the start is inside
    assert values["t_lateral"] == pytest.approx(plain["t_lateral"] * math.hypot(1, CORNER_SLOPE))
    assert values["t_max"] > plain["t_max"]
    # the roll lifts the low corner by w sin(roll) as it turns upright: the tilt is left less
    rise = 4.5e-4 - 0.004 * math.sin(CORNER_ROLL)
    assert domains["tilt"].high == pytest.approx(math.asin(rise / 0.006))
    chamfered, _ = fit_context(
        FitGeometry(0.006, 1e-4, 5e-4, 5e-4, corner=0.004), DEFAULTS, 0.25, TILT
    )
    assert "roll" not in chamfered and "lateral_dir_y" not in chamfered  # a chamfer catches


def test_fit_of_gives_a_non_round_part_its_corner() -> None:
    from types import SimpleNamespace

    from teachfit.skills.fit_context import fit_of

    base = {"part_half_width": 0.006, "clearance": 1e-4, "tip_chamfer": 0.0}
    rect = SimpleNamespace(**base, part_half_depth=0.004, rz_period=math.pi)
    round_ = SimpleNamespace(**base, part_half_depth=0.006, rz_period=0.0)
    assert fit_of(rect).corner == 0.004  # type: ignore[union-attr]
    assert fit_of(round_).corner == 0.0  # type: ignore[union-attr]
