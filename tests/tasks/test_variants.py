import numpy as np
import pytest

from teachfit.core.errors import TaskError
from teachfit.execution.teacher import TeacherStyle, style_for
from teachfit.tasks.registry import get_task
from teachfit.tasks.variants import AXES, grid, sample_variants, variant


def test_grids_cover_the_issue_ranges_and_build_valid_tasks():
    peg = grid("peg2d")
    assert len(peg) == np.prod([len(v) for v in AXES["peg2d"].values()])
    sock = grid("socket3d")
    # the small hole's clearance is never above the large one's
    assert all(
        dict(v.values)["clearance_small_mm"] <= dict(v.values)["clearance_large_mm"] for v in sock
    )
    task = variant("peg2d", peg_diameter_mm=8, clearance_mm=0.2, friction=0.8, chamfers=0).make()
    assert task.params.peg_diameter == pytest.approx(0.008)
    assert task.params.peg_chamfer == 0 and task.params.hole_chamfer == 0
    assert task.scene.contact.friction == pytest.approx(0.8)  # the scene follows the variant
    s = variant("socket3d", start_rz_deg=10, clearance_small_mm=0.3, clearance_large_mm=0.5)
    assert s.make().params.start_rz == pytest.approx(np.radians(10))


def test_sample_is_seeded_distinct_and_refuses_bad_input():
    a, b = sample_variants("peg2d", 12, seed=3), sample_variants("peg2d", 12, seed=3)
    assert a == b and len(set(a)) == 12
    assert sample_variants("peg2d", 12, seed=4) != a
    assert len(sample_variants("socket3d", 1000)) == len(grid("socket3d"))
    with pytest.raises(TaskError, match="no variant grid"):
        sample_variants("puzzle", 2)
    with pytest.raises(TaskError, match="axes"):
        variant("peg2d", friction=0.3)


def test_peg2d_teacher_hints_follow_the_capture_width_and_friction():
    default = style_for(get_task("peg2d"))
    # the default cell keeps the default sweep (its published tables were recorded with it)
    for name in ("spiral_pitch", "sweep_halfwidth", "max_duration"):
        assert getattr(default, name) == getattr(TeacherStyle(), name)
    sharp = style_for(get_task("peg2d", clearance=0.0003, peg_chamfer=0.0, hole_chamfer=0.0))
    # sharp edges: the hand tilts the peg, rows within the tilted peg's 1 mm capture
    assert sharp.tilt == 0.25 and sharp.spiral_pitch <= 1.6 * 0.001 + 1e-12
    assert sharp.tilt_reach == pytest.approx(0.0203)  # slid across the hole after the drop
    assert default.tilt == 0.0
    assert sharp.max_duration > default.max_duration and sharp.hold_depth == pytest.approx(5e-4)
    sticky = style_for(get_task("peg2d", friction=0.8))
    assert sticky.sweep_halfwidth > default.sweep_halfwidth
    # a style given by the user wins over the hints
    assert (
        style_for(
            get_task("peg2d", friction=0.8), TeacherStyle(sweep_halfwidth=0.01)
        ).sweep_halfwidth
        == 0.01
    )
