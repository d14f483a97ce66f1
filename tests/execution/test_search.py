import math

import numpy as np
import pytest

from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import Pose
from teachfit.execution.search import TRACK_FEEL, plan_search, run_search, search_setpoints
from teachfit.execution.teacher import BlindTeacher
from teachfit.models.search_model import SearchModel
from teachfit.robot.floating import FloatingToolRobot
from teachfit.tasks import get_task
from teachfit.trajectories import SearchTrajectory


@pytest.fixture(scope="module")
def peg_model():
    task = get_task("peg2d")
    demos, _ = BlindTeacher(task, seed=1).record(1)
    return task, demos[0], SearchModel.fit(demos, task.name)


def test_setpoints_translate_the_search_frame_and_add_yaw():
    task = get_task("socket3d")
    t = np.array([0.0, 1.0, 2.0])
    states = np.array([[0.0, 0.0, 0.0], [0.01, -0.002, 0.1], [0.02, 0.0, -0.2]])
    traj = SearchTrajectory(t, states, ("x", "y", "rz"), "test")
    start = Pose.from_xyz_rz(0.003, 0.004, task.surface_z, 0.3)
    sp = search_setpoints(traj, task, start)
    assert np.allclose(sp.pos[:, :2], states[:, :2] + [0.003, 0.004])
    assert np.allclose(sp.pos[:, 2], task.surface_z)
    yaw = 2 * np.arctan2(sp.quat[:, 3], sp.quat[:, 0])
    assert np.allclose(yaw, 0.3 + states[:, 2])
    assert np.allclose(sp.wrench_ff, 0.0)  # no model: no feed-forward
    with pytest.raises(TeachfitError, match="dims"):
        search_setpoints(traj, get_task("peg2d"), start)


def test_feedforward_from_the_dynamics_model(peg_model):
    task, _, model = peg_model
    traj = plan_search(model, "tshix", 30, np.random.default_rng(0))
    start = task.contact_pose([0.02, 0.0])
    sp = search_setpoints(traj, task, start, model)
    gmr = model.feedforward_along(traj.t, traj.states)
    ff = sp.wrench_ff[:, :2]
    assert np.allclose(sp.wrench_ff[:, 2:], 0.0)
    # the teacher pushed against friction: the action points along the motion on average
    vel = np.gradient(traj.states, traj.t, axis=0)
    assert np.mean(np.sum(vel * gmr, axis=1)) > 0
    # what is commanded is the GMR's force along the motion, never across or backwards
    u = vel / np.linalg.norm(vel, axis=1, keepdims=True)
    along = np.sum(gmr * u, axis=1)
    assert np.allclose(ff, np.clip(along, 0, None)[:, None] * u)
    assert np.allclose(ff[:, 0] * u[:, 1] - ff[:, 1] * u[:, 0], 0.0)


def test_search_finds_the_hole_from_the_demo_start(peg_model):
    task, demo, model = peg_model
    robot = FloatingToolRobot(task)
    start = Pose(demo.pos[0], demo.quat[0])
    successes = 0
    for seed in (2, 8):  # at least one of two seeded plans inserts (seed 2: at 8.5 s of 26 s)
        traj = plan_search(model, "tshix", 100, np.random.default_rng(seed))
        run = run_search(robot, task, model, start, traj)
        successes += run.result.success
        assert run.result.log.pos.shape[0] > 10
        if successes:
            break  # one insertion is all this asserts
    assert successes >= 1


def test_methods_and_bad_input(peg_model):
    _, _, model = peg_model
    rng = np.random.default_rng(0)
    for method in ("ergodic", "spiral", "random-walk"):
        traj = plan_search(model, method, 50, rng)
        assert traj.states.shape[1] == 2 and traj.duration > 1.0
    for n in (0, 100_000_000):  # a limit: 1e8 points would take minutes and GBs
        with pytest.raises(TeachfitError, match=r"must be 1 \.\.\. 10000"):
            plan_search(model, "tshix", n, rng)
    with pytest.raises(TeachfitError, match="unknown search method"):
        plan_search(model, "telepathy", 10, rng)


def test_passes_append_resampled_tshix_passes(peg_model):
    _, _, model = peg_model
    one = plan_search(model, "tshix", 40, np.random.default_rng(5))
    three = plan_search(model, "tshix", 40, np.random.default_rng(5), passes=3)
    assert three.meta["passes"] == 3 and three.samples.shape[0] == 120
    assert np.allclose(three.states[: one.states.shape[0]], one.states)  # the first pass is kept
    assert three.duration > 2.5 * one.duration
    # later passes draw new samples, they do not repeat the first
    assert not np.allclose(three.samples[40:80], three.samples[:40])
    with pytest.raises(TeachfitError, match="passes"):
        plan_search(model, "ergodic", 40, np.random.default_rng(5), passes=2)
    with pytest.raises(TeachfitError, match="passes"):
        plan_search(model, "tshix", 40, np.random.default_rng(5), passes=0)


def test_follower_config_from_the_task():
    from teachfit.execution.search import task_follow_config
    from teachfit.skills.follow import FollowConfig

    base = FollowConfig()
    cfg = task_follow_config(get_task("peg2d"))
    assert (cfg.stiffness_along, cfg.stiffness_across) == (1500.0, 150.0)
    assert cfg.hold_depth == pytest.approx(0.001) and cfg.hold_stiffness == 150.0
    slick = task_follow_config(get_task("peg2d", friction=0.8))  # same lag as at 0.3
    assert slick.stiffness_along * 0.3 == pytest.approx(base.stiffness_along * 0.8)
    assert slick.hold_stiffness == slick.stiffness_across == pytest.approx(400.0)
    socket = task_follow_config(get_task("socket3d"))  # no hints: the defaults, lag closed
    assert socket == FollowConfig(track_feel=TRACK_FEEL) and base.track_feel == 0.0


def test_sharp_edged_holes_are_searched_tilted_chamfered_ones_upright():
    from teachfit.execution.search import task_follow_config
    from teachfit.skills.follow import FollowConfig
    from teachfit.tasks.variants import grid

    default = task_follow_config(get_task("peg2d"))  # the default cell's follower as before
    assert default == FollowConfig(
        hold_depth=default.hold_depth, hold_stiffness=150.0, track_feel=TRACK_FEEL
    )
    assert default.tilt is None
    for v in grid("peg2d"):
        task = v.make()
        tilt = task_follow_config(task).tilt
        assert (tilt is None) == bool(dict(v.values)["chamfers"]), v.label
        if tilt is not None:
            hole = task.params.peg_diameter + task.params.clearance
            assert tilt.lateral_reach == pytest.approx(hole)


def test_feedforward_never_below_the_sliding_friction_while_moving():
    from teachfit.execution.search import along_motion, friction_floor
    from teachfit.skills.follow import FollowConfig

    t = np.array([0.0, 1.0, 2.0, 3.0])
    states = np.array([[0.0, 0.0], [0.01, 0.0], [0.01, 0.01], [0.01, 0.01]])  # +x, +y, rest
    gmr = np.array([[0.5, 3.0], [4.0, 0.0], [0.0, 0.2], [1.0, 1.0]])
    out = along_motion(gmr, t, states, ("x", "y"), floor=2.0)
    assert out[0] == pytest.approx([2.0, 0.0])  # 0.5 N along +x: raised to the floor
    assert out[1][0] == pytest.approx(out[1][1])  # the turn's direction is the diagonal
    assert np.linalg.norm(out[1]) == pytest.approx(max(2.0, 4.0 / np.sqrt(2)))
    assert np.allclose(out[3], 0.0)  # at rest: nothing
    assert np.allclose(along_motion(gmr, t, states, ("x", "y"))[0], [0.5, 0.0])
    push = FollowConfig().push_force
    assert friction_floor(get_task("peg2d"), FollowConfig()) == pytest.approx(0.3 * (push + 0.981))
    assert friction_floor(get_task("socket3d"), FollowConfig()) == 0.0  # no hint: no floor


def test_a_fit_task_s_sharp_part_is_searched_as_the_joined_skill_searches_it():
    from types import SimpleNamespace

    from teachfit.execution.search import FIT_TILT_RAMP, task_follow_config
    from teachfit.skills.fit_context import FitGeometry, search_tilt_context
    from teachfit.skills.tilt import rim_lead

    params = SimpleNamespace(hole_pos_sigma=5e-4, friction=0.3)
    sharp = SimpleNamespace(part_half_width=0.008, clearance=1e-4, tip_chamfer=0.0, params=params)
    tilt = task_follow_config(sharp).tilt  # type: ignore[arg-type]
    want = search_tilt_context(FitGeometry(0.008, 1e-4, 0.0, 5e-4))
    assert tilt is not None and tilt.angle == want["search_tilt"]
    assert tilt.lead == pytest.approx(want["search_lead"])
    assert tilt.lateral_reach == pytest.approx(want["search_reach"])
    assert tilt.drop_depth == want["search_drop"] and tilt.ramp_time == FIT_TILT_RAMP
    assert tilt.retry_angle == pytest.approx(want["search_retry_tilt"])  # acos(8/8.1) < 0.25
    chamfered = SimpleNamespace(**{**vars(sharp), "tip_chamfer": 5e-4})
    assert task_follow_config(chamfered).tilt is None  # type: ignore[arg-type]
    assert tilt.corner is None  # round: the tilt follows the path
    rect = SimpleNamespace(**{**vars(sharp), "part_half_width": 0.006})
    rect.part_half_depth, rect.rz_period = 0.004, math.pi
    corner = task_follow_config(rect).tilt  # type: ignore[arg-type]
    assert corner is not None and corner.corner == pytest.approx(math.atan2(0.004, 0.006))
    assert corner.lead == pytest.approx(rim_lead(corner.angle, 2 * math.hypot(0.006, 0.004)))
