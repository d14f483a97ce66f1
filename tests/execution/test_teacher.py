import dataclasses

import numpy as np
import pytest

from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import Pose
from teachfit.execution.teacher import BlindTeacher, TeacherStyle, style_for
from teachfit.execution.teacher_cache import ENV as CACHE_ENV
from teachfit.robot.floating import FloatingToolRobot
from teachfit.robot.fr3 import FR3Robot
from teachfit.tasks import get_task
from teachfit.tasks.registry import load_task

pytestmark = pytest.mark.usefixtures("no_teacher_cache")

SPIRAL = TeacherStyle(pattern="spiral")


@pytest.fixture(scope="module")
def spiral_demo():
    """A spiral demonstration of peg2d, seed 7, recorded for real (the teacher cache unset, as
    for every test here): it inserts after 5 s, where the default sweep's take 30 s."""
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv(CACHE_ENV, raising=False)
        (demo,), _ = BlindTeacher(get_task("peg2d"), SPIRAL, seed=7).record(1)
    return demo


def test_same_seed_same_demo(spiral_demo):
    (again,), _ = BlindTeacher(get_task("peg2d"), SPIRAL, seed=7).record(1)
    assert np.array_equal(again.pos, spiral_demo.pos)
    assert np.array_equal(again.wrench, spiral_demo.wrench)


def test_demos_that_end_at_once_or_never_are_discarded():
    task = get_task("peg2d")
    teacher = BlindTeacher(task, seed=0)
    demo, why = teacher.demonstrate(task.contact_pose([0.0, 0.0]).translated([0, 0, 0.001]))
    assert demo is None and "at once" in why
    lazy = BlindTeacher(task, TeacherStyle(max_duration=0.6, min_duration=0.1), seed=0)
    demo, why = lazy.demonstrate()
    assert demo is None and "never" in why
    with pytest.raises(TeachfitError, match="succeeded"):
        lazy.record(1, max_attempts=2)


def test_worst_case_sweep_spans_start_to_hole_and_across():
    """Ehlers et al. 2019: one end of the exploration distribution is at the demonstration's
    start."""
    task = get_task("peg2d")
    demos, _ = BlindTeacher(task, seed=2).record(1)
    xy = demos[0].pos[:, :2]
    hole = task.hole2world.pos[:2]
    axis = (hole - xy[0]) / np.linalg.norm(hole - xy[0])
    along = (xy - xy[0]) @ axis
    across = (xy - xy[0]) @ np.array([-axis[1], axis[0]])
    style = TeacherStyle()
    assert along.min() < 0.003 and along.max() > 0.8 * task.params.demo_offset
    assert across.max() - across.min() > 1.5 * style.sweep_halfwidth


def test_other_patterns_go_straight_towards_the_belief(spiral_demo):
    task = get_task("peg2d")
    xy = spiral_demo.pos[:, :2]
    assert np.linalg.norm(xy[-1] - task.hole2world.pos[:2]) < task.capture_radius


def test_builtin_tasks_keep_the_default_style():
    # the default peg2d keeps the default sweep; its hand only stops once the peg is in the bore
    assert style_for(get_task("peg2d")) == TeacherStyle(hold_depth=0.002)
    assert style_for(get_task("socket3d")) == TeacherStyle()
    assert style_for(get_task("peg2d"), TeacherStyle(pattern="spiral")).pattern == "spiral"


def test_an_arm_slows_the_teacher_only_on_tasks_that_search_in_rz():
    arm = FR3Robot  # the hints are the class's table: no model needs building
    socket = style_for(get_task("socket3d"), robot=arm)
    # the one per-robot table gives what the former two did (press by feel everywhere, the
    # slower hand in rz only), field for field
    arm_hand = {"press_feel": 0.15, "hand_smoothing": 0.1}
    assert socket == TeacherStyle(speed=0.006, rz_wiggle_frequency=0.15, **arm_hand)
    peg2d = get_task("peg2d")
    # Table I's stays as on the tool, but for the press by feel and the smoother hand
    assert style_for(peg2d, robot=arm) == dataclasses.replace(style_for(peg2d), **arm_hand)
    explicit = style_for(get_task("socket3d"), TeacherStyle(speed=0.02), robot=arm)
    assert explicit.speed == 0.02  # an explicit choice wins over the robot's hints
    assert explicit.rz_wiggle_frequency == 0.15
    for name in ("peg2d", "socket3d", "puzzle"):  # the floating tool has no hints
        task = get_task(name)
        assert FloatingToolRobot.teacher_hints(task).overrides() == {}
        assert style_for(task, robot=FloatingToolRobot) == style_for(task)


def test_mesh_task_scales_the_teacher_to_its_fit(mesh_examples):
    task = load_task(mesh_examples["usb"])
    style = style_for(task, TeacherStyle(speed=0.02))
    assert style.speed == 0.02  # an explicit choice wins over the task's hints
    assert style.spiral_pitch <= task.capture_radius  # every raster row can catch the entry
    assert style.rz_wiggle < task.rz_tolerance and style.rz_belief_sigma < task.rz_tolerance
    assert task.params.demo_offset + style.sweep_halfwidth < task.detection_radius
    demos, discarded = BlindTeacher(task, seed=0).record(1, max_attempts=1)
    assert discarded == [] and task.ground_truth_inserted(Pose(demos[0].pos[-1], demos[0].quat[-1]))


def test_unchamfered_yaw_task_gets_a_fine_spiral_inside_its_yaw_tolerance():
    puzzle = get_task("puzzle")
    style = style_for(puzzle)
    assert style.pattern == "spiral"
    assert style.spiral_pitch == pytest.approx(puzzle.params.clearance)
    assert style.rz_wiggle < puzzle.rz_tolerance and style.rz_belief_sigma < puzzle.rz_tolerance
    assert style.arm_stiffness > TeacherStyle().arm_stiffness  # a firm hand: a straight spiral
    # an asked-for pattern and asked-for fields stay; chamfered or yaw-free tasks are unchanged
    zigzag = style_for(puzzle, TeacherStyle(pattern="zigzag", rz_wiggle=0.3))
    assert zigzag.pattern == "zigzag" and zigzag.rz_wiggle == 0.3
    assert zigzag.spiral_pitch == pytest.approx(puzzle.params.clearance)
    for name in ("key", "peg", "socket3d"):
        assert style_for(get_task(name)) == TeacherStyle()
    peg2d = get_task("peg2d")  # its default cell keeps the default sweep, and holds after a drop
    assert style_for(peg2d) == TeacherStyle(hold_depth=peg2d.hold_depth)


def test_blind_teacher_inserts_the_unchamfered_puzzle_piece():
    task = get_task("puzzle")  # 0/10 demonstrations with the default sweep
    demo, why = BlindTeacher(task, seed=0).demonstrate()
    assert demo is not None, why
    assert task.ground_truth_inserted(Pose(demo.pos[-1], demo.quat[-1]))


def test_the_press_wanders_slowly_seeded_and_stays_apart_from_the_other_draws():
    task = get_task("peg2d")
    still = BlindTeacher(task, TeacherStyle(press_wander=0.0), seed=4)
    a, b = BlindTeacher(task, seed=4), BlindTeacher(task, seed=4)
    start = task.contact_pose([0.03, 0.0])
    plan_a, plan_b, plan_still = a.plan(start), b.plan(start), still.plan(start)
    assert np.array_equal(plan_a.wrench_ff, plan_b.wrench_ff)
    assert np.array_equal(plan_a.pos, plan_still.pos)  # its own random stream
    assert np.all(plan_still.wrench_ff == 0.0)
    dev = -plan_a.wrench_ff[:, 2]  # the press's deviation from push_force, 100 Hz, 60 s
    assert 0.2 < dev.std() < 0.4  # press_wander 0.3 N
    assert np.corrcoef(dev[:-1], dev[1:])[0, 1] > 0.98  # time constant 1 s: slow
    assert np.all(plan_a.wrench_ff[:, [0, 1, 3, 4, 5]] == 0.0)


def test_a_smoothed_hand_keeps_its_draws_and_loses_its_jerk():
    task = get_task("peg2d")
    start = task.contact_pose([0.03, 0.0])
    raw, smooth = (
        BlindTeacher(task, TeacherStyle(hand_smoothing=tau), seed=4).plan(start) for tau in (0, 0.1)
    )
    # the same path within the wander's reach (0.5 mm std), its 100 Hz velocity steps gone
    dev = np.linalg.norm(smooth.pos - raw.pos, axis=1)
    assert dev.max() < 2e-3 and dev.mean() < 5e-4
    jerk = [np.diff(p.pos[:, :2], 2, axis=0).std() for p in (raw, smooth)]
    assert jerk[1] < 0.2 * jerk[0]
    assert BlindTeacher(task, seed=4).plan(start).pos == pytest.approx(raw.pos)  # default: none
    with pytest.raises(TeachfitError, match="hand_smoothing"):
        TeacherStyle(hand_smoothing=-0.1)


def test_the_arm_teacher_presses_by_feel_the_floating_one_open_loop():
    task = get_task("peg2d")
    assert BlindTeacher(task, seed=0).style.press_feel == 0.0
    assert BlindTeacher(task, seed=0, robot="fr3").style.press_feel > 0.0
    with pytest.raises(TeachfitError, match="press_wander"):
        TeacherStyle(press_wander=7.0)
