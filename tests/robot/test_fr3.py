"""The simulated FR3 behind the Robot protocol: model, torque law, limits, sensing, faults."""

import mujoco
import numpy as np
import pytest

from teachfit.control import AdaptiveImpedance, CartesianImpedance
from teachfit.core.control import AdaptiveSpec, FixedGainSpec, ImpedanceLimits
from teachfit.core.errors import LimitViolation, SimulationDiverged, TeachfitError
from teachfit.core.state import ImpedanceCommand
from teachfit.robot import make_robot
from teachfit.robot.fr3 import FR3Params, FR3Robot
from teachfit.robot.fr3.model import HAND_CLEARANCE, JOINTS, PART_PREFIX, fixture_top, grasp_drop
from teachfit.robot.fr3.params import BREAKAWAY_RATIO, DTAU_MAX, GAZ_PHI1, Q_MAX, Q_MIN, TAU_MAX
from teachfit.robot.interface import Robot
from teachfit.tasks import get_task


@pytest.fixture(scope="module")
def task():
    return get_task("peg2d")


@pytest.fixture(scope="module")
def robot(task):
    return FR3Robot(task)


def free_pose(task, dx=0.0):
    """A TCP pose 3 cm above the block, in free space."""
    return task.contact_pose(np.array([0.03 + dx, 0.0])).translated([0.0, 0.0, 0.03])


def test_is_a_registered_robot_with_torque_motors(task, robot):
    assert isinstance(robot, Robot)
    assert robot.name == "fr3" and robot.wrench_source == "joint-torques"
    assert robot.control_period == pytest.approx(0.001)
    m = robot.model
    assert m.nu == m.nv == m.nq == 7
    np.testing.assert_allclose(m.actuator_gainprm[:, 0], 1.0)
    assert np.all(m.actuator_biastype == mujoco.mjtBias.mjBIAS_NONE)
    np.testing.assert_allclose(m.actuator_ctrlrange[:, 1], TAU_MAX)
    np.testing.assert_allclose(m.jnt_range, np.column_stack([Q_MIN, Q_MAX]))
    np.testing.assert_allclose(m.dof_frictionloss, np.asarray(GAZ_PHI1) / 2)
    assert [m.joint(i).name for i in range(m.njnt)] == list(JOINTS)
    # the task's cell stays where the task builds it: the fixture at the world origin
    np.testing.assert_allclose(m.body("fixture").pos, 0.0)
    # the hand collides, the part is on the hand
    hand = m.body("fr3/hand").id
    assert any(m.geom_bodyid[g] == hand and m.geom_contype[g] for g in range(m.ngeom))
    assert m.body_parentid[m.body(f"{PART_PREFIX}held_part").id] == hand
    wft = make_robot("fr3", task, sensor="wrist-ft")
    assert wft.wrench_source == "wrist-ft"
    with pytest.raises(TeachfitError, match="bogus"):
        make_robot("fr3", task, bogus=1)


def test_reset_places_the_tcp_at_the_pose_at_rest(task, robot):
    pose = free_pose(task)
    state = robot.reset(pose)
    np.testing.assert_allclose(state.pos, pose.pos, atol=1e-6)
    assert abs(float(np.dot(state.quat, pose.quat))) > 1 - 1e-9
    np.testing.assert_allclose(state.twist, 0.0, atol=1e-12)
    np.testing.assert_allclose(state.wrench[:3], 0.0, atol=0.3)


def test_gravity_compensated_hold_drifts_less_than_a_tenth_of_a_millimetre(task, robot):
    pose = free_pose(task)
    robot.reset(pose)
    state = robot.step(2000)
    assert np.linalg.norm(state.pos - pose.pos) < 1e-4
    # and it is the controller that holds it: without torques the arm falls
    robot.reset(pose)
    robot.ctl.tau_max = np.zeros(7)
    try:
        fallen = robot.step(200)
    except LimitViolation:
        fallen = None
    finally:
        robot.ctl.tau_max = np.asarray(TAU_MAX, dtype=float)
    assert fallen is None or np.linalg.norm(fallen.pos - pose.pos) > 1e-3


def test_tracks_a_moving_set_point_in_free_space(task, robot):
    pose = free_pose(task)
    robot.reset(pose)
    v = np.array([0.0, 0.05, 0.0])
    robot.command(ImpedanceCommand.hold(pose, lin_vel=v, expires_after=0.4))
    errors = []
    for k in range(1, 41):
        state = robot.step(10)
        target = pose.pos + v * min(0.01 * k, 0.4)
        errors.append(np.linalg.norm(state.pos - target))
    assert max(errors) < 0.005  # within 5 mm while moving at 5 cm/s (K = 1000 N/m)
    state = robot.step(600)
    np.testing.assert_allclose(state.pos, pose.pos + v * 0.4, atol=5e-4)


def test_torque_and_torque_rate_limits_hold_every_tick(task):
    spec = FixedGainSpec(limits=ImpedanceLimits(max_force=2000.0, max_torque=300.0))
    robot = FR3Robot(task, controller=spec)
    pose = free_pose(task)
    robot.reset(pose)
    robot.command(
        ImpedanceCommand.hold(pose.translated([0.0, 0.2, 0.0]), stiffness=[2e4] * 3 + [500] * 3)
    )
    prev = robot.joint_torques
    steps, saturated = [], []
    for _ in range(40):  # before the arm reaches its joint speed limits
        robot.step(1)
        tau = robot.data.ctrl.copy()
        steps.append(np.abs(tau - prev).max())
        saturated.append(np.abs(tau) >= np.asarray(TAU_MAX) - 1e-9)
        assert np.all(np.abs(tau) <= np.asarray(TAU_MAX) + 1e-9)
        prev = tau
    assert max(steps) <= DTAU_MAX * robot.control_period + 1e-9
    assert max(steps) == pytest.approx(DTAU_MAX * robot.control_period)  # the rate limit acted
    assert np.any(saturated)  # and so did the magnitude limit


def test_joint_friction_holds_a_small_disturbance(task):
    robot = FR3Robot(task, params=FR3Params(null_stiffness=0.0, null_damping=0.0))
    moved = []
    for torque in (0.2, 1.0):  # joint 7's dry friction is 0.28 N·m
        pose = free_pose(task)
        robot.reset(pose)
        robot.command(ImpedanceCommand.hold(pose, stiffness=0.0, damping=0.0))
        q0 = robot.data.qpos.copy()
        robot.data.qfrc_applied[6] = torque
        robot.step(500)
        moved.append(abs(robot.data.qpos[6] - q0[6]))
    # MuJoCo's dry friction is a soft constraint: below the threshold it creeps (< 1 mrad in
    # 0.5 s), above it the joint slides freely
    assert moved[0] < 1e-3
    assert moved[1] > 30 * moved[0] and moved[1] > 1e-2


@pytest.mark.parametrize(
    ("sensor", "friction", "ratio"),
    [
        ("joint-torques", 1.0, 1.0),
        ("joint-torques", 0.0, 1.0),
        ("wrist-ft", 1.0, 1.0),
        ("joint-torques", 1.0, BREAKAWAY_RATIO),  # a static peak and the Stribeck term
    ],
)
def test_estimated_external_wrench_matches_an_applied_force(task, sensor, friction, ratio):
    params = FR3Params(
        sensor=sensor,
        torque_noise=0.0,
        ft_noise=(0, 0),
        joint_friction=friction,
        breakaway_ratio=ratio,
    )
    robot = FR3Robot(task, params=params)
    assert np.all(  # MuJoCo's dry friction holds up to the static level
        robot.model.dof_frictionloss == pytest.approx(np.asarray(GAZ_PHI1) / 2 * friction * ratio)
    )
    pose = free_pose(task)
    robot.reset(pose)
    force = np.array([4.0, -3.0, -8.0])
    m, d = robot.model, robot.data
    part = m.body(f"{PART_PREFIX}held_part").id
    for _ in range(600):  # a constant force at the TCP (a body wrench at the part's centre of mass)
        lever = d.site_xpos[robot._tcp] - d.xipos[part]
        d.xfrc_applied[part, :3] = force
        d.xfrc_applied[part, 3:] = np.cross(lever, force)
        state = robot.step(1)
    assert np.linalg.norm(state.wrench[:3] - force) < 0.05 * np.linalg.norm(force)
    assert np.linalg.norm(state.wrench[3:]) < 0.05 * np.linalg.norm(force) * 0.1


def test_ik_reaches_every_table1_start_of_peg2d(task, robot):
    starts = task.protocol.protocol_starts("table1", 30, np.random.default_rng(3))
    for pose in starts:
        state = robot.reset(pose)
        np.testing.assert_allclose(state.pos, pose.pos, atol=1e-5)
        q = robot.data.qpos
        assert np.all(q >= Q_MIN) and np.all(q <= Q_MAX)


def test_unreachable_pose_is_a_limit_violation(task, robot):
    with pytest.raises(LimitViolation, match="IK"):
        robot.reset(task.contact_pose(np.array([1.5, 0.0])))


def insert(task, offset):
    """Lower the part at 10 mm/s from 2 mm above the entry, laterally stiff (the joints' dry
    friction leaves an alignment error of about 1 N / K_xy)."""
    robot = FR3Robot(task)
    start = task.contact_pose(np.array([offset, 0.0])).translated([0.0, 0.0, 0.002])
    robot.reset(start)
    robot.command(
        ImpedanceCommand.hold(
            start,
            lin_vel=[0.0, 0.0, -0.01],
            wrench_ff=[0.0, 0.0, -3.0, 0.0, 0.0, 0.0],
            stiffness=[6000, 6000, 1000, 50, 50, 50],
            expires_after=3.0,
        )
    )
    return robot.step(2000)


def test_aligned_peg_inserts_and_one_millimetre_off_is_blocked():
    task = get_task("peg2d", clearance=0.0002, peg_chamfer=0.0, hole_chamfer=0.0)
    aligned = insert(task, 0.0)
    assert task.ground_truth_inserted(aligned.pose)
    assert task.insertion_depth(aligned.pose) > 0.015
    off = insert(task, 0.001)
    assert not task.ground_truth_inserted(off.pose)
    assert abs(task.insertion_depth(off.pose)) < 2e-4
    assert off.wrench[2] > 5.0


def test_the_hand_clears_the_socket_wall_with_the_plug_past_its_success_depth():
    socket = get_task("socket3d")
    wall_top = socket.surface_z + socket.params.recess_depth
    assert fixture_top(socket) == pytest.approx(wall_top, abs=1e-6)
    drop = grasp_drop(socket)  # held this much lower in the fingers than flush under the hand
    inserted = socket.hole2world.pos[2] - socket.success_depth - 0.002
    hand_bottom = inserted + socket.scene.held_part_length + drop
    assert drop > 0.004 and hand_bottom >= wall_top + HAND_CLEARANCE - 1e-6
    assert grasp_drop(get_task("peg2d")) == 0.0  # the parts that clear keep their grasp


def test_limit_violation_and_divergence_are_latched_until_reset(task, robot):
    pose = free_pose(task)
    robot.reset(pose)
    robot.data.qpos[3] = Q_MAX[3] + 0.05
    with pytest.raises(LimitViolation, match="joint 4"):
        robot.step(1)
    with pytest.raises(LimitViolation):
        robot.command(ImpedanceCommand.hold(pose))
    robot.reset(pose)
    robot.data.qvel[0] = np.nan
    with pytest.raises(SimulationDiverged):
        robot.step(2)
    with pytest.raises(SimulationDiverged):
        robot.step(1)
    assert np.allclose(robot.reset(pose).pos, pose.pos, atol=1e-5)
    robot.step(5)


def test_reset_switches_the_control_law(task, robot):
    robot.reset(free_pose(task), controller=AdaptiveSpec())
    assert isinstance(robot.law, AdaptiveImpedance)
    state = robot.step(300)
    assert np.linalg.norm(state.pos - free_pose(task).pos) < 1e-3
    robot.reset(free_pose(task), controller=FixedGainSpec())
    assert isinstance(robot.law, CartesianImpedance)
    # the law's damping uses the arm's operational-space inertia at the start configuration
    assert np.all(robot.apparent_mass > 0) and robot.apparent_mass[0] > 1.0
