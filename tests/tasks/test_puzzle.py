"""The ``puzzle`` task, and Johannsmeier et al.'s start protocol shared by ``puzzle``, ``key``
and ``peg``."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolRobot, build_scene
from teachfit.tasks import Puzzle, PuzzleParams, SkillTask, get_task, load_task

STIFF = [300, 300, 300, 50, 50, 50]
SEED_B_TASKS = ["puzzle", "key", "peg"]


@pytest.fixture(scope="module")
def task() -> Puzzle:
    t = get_task("puzzle")
    assert isinstance(t, Puzzle)
    return t


@pytest.fixture(scope="module")
def robot(task: Puzzle) -> FloatingToolRobot:
    return FloatingToolRobot(task)


def push(robot: FloatingToolRobot, x: float, y: float, rz: float, steps: int = 800) -> Pose:
    """Start 2 mm above the entry at (x, y, rz) in the hole frame and push down softly."""
    start = robot.task.hole2world.compose(Pose.from_xyz_rz(x, y, 0.002, rz))
    robot.reset(start)
    robot.command(ImpedanceCommand(pos=start.pos - [0, 0, 0.03], quat=start.quat, stiffness=STIFF))
    return robot.step(steps).pose


def test_scene_is_three_convex_walls_and_a_base(task: Puzzle) -> None:
    model = mujoco.MjModel.from_xml_string(build_scene(task))
    names = {model.geom(i).name for i in range(model.ngeom)}
    assert {"hole_wall_0", "hole_wall_1", "hole_wall_2", "fixture_base", "puzzle_piece"} <= names
    assert Puzzle.rz_period == pytest.approx(2 * np.pi / 3)
    assert task.search_dims == ("x", "y", "rz")


@pytest.mark.parametrize("rz", [0.0, 2 * np.pi / 3])
def test_aligned_piece_enters_to_the_bottom(robot, task, rz) -> None:
    pose = push(robot, 0.0, 0.0, rz)
    assert task.insertion_depth(pose) > task.params.hole_depth - 2e-4
    assert task.ground_truth_inserted(pose)


@pytest.mark.parametrize("offset", [(0.0015, 0.0), (-0.0015, 0.0), (0.0, 0.0015)])
def test_offset_piece_is_blocked(robot, task, offset) -> None:
    pose = push(robot, *offset, 0.0)
    assert abs(task.insertion_depth(pose)) < 2e-4  # rests on the block: no chamfer guides it
    assert not task.ground_truth_inserted(pose)


@pytest.mark.parametrize("deg", [3.0, 25.0])
def test_rotated_piece_is_blocked(robot, task, deg) -> None:
    pose = push(robot, 0.0, 0.0, np.deg2rad(deg))
    assert abs(task.insertion_depth(pose)) < 2e-4
    assert not task.ground_truth_inserted(pose)


def test_turned_hole_needs_the_turned_piece() -> None:
    turned = Puzzle(PuzzleParams(hole_yaw=0.4))
    robot = FloatingToolRobot(turned)
    assert turned.ground_truth_inserted(push(robot, 0.0, 0.0, 0.0))  # in the hole frame: aligned
    start = Pose.from_xyz_rz(0.0, 0.0, turned.surface_z + 0.002, 0.0)  # world yaw 0: 0.4 off
    robot.reset(start)
    robot.command(ImpedanceCommand(pos=start.pos - [0, 0, 0.03], quat=start.quat, stiffness=STIFF))
    assert not turned.ground_truth_inserted(robot.step(800).pose)


def test_ground_truth_inserted_checks_depth_axis_and_yaw(task: Puzzle) -> None:
    z = task.surface_z - 0.012
    assert task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z, 0.0))
    assert task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z, 4 * np.pi / 3))  # 3-fold symmetric
    assert not task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z, 0.2))
    assert not task.ground_truth_inserted(Pose.from_xyz_rz(0.001, 0, z, 0.0))
    assert not task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, task.surface_z - 0.005, 0.0))
    assert task.yaw_error(Pose.from_xyz_rz(0, 0, z, 2 * np.pi / 3 + 0.1)) == pytest.approx(0.1)


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"clearance": 0.0}, "clearance must be > 0"),
        ({"clearance": -0.0001}, "clearance must be > 0"),
        ({"clearance": 0.01}, "no tight fit"),
        ({"hole_chamfer": -0.001}, "hole_chamfer"),
        ({"block_half_width": 0.02, "demo_offset": 0.001}, "rim"),
        ({"hole_depth": 0.039}, "hole bottom"),
        ({"success_depth": 0.02}, "deeper than the hole"),
        ({"piece_height": 0.01}, "piece_height"),
        ({"demo_offset": 0.03}, "off the block"),
        ({"start_yaw": 1.0}, "start_yaw"),
        ({"approach_height": 0.0}, "approach_height"),
        ({"hole_pos_sigma": -1.0}, "hole_pos_sigma"),
    ],
)
def test_impossible_parameters(overrides, match) -> None:
    with pytest.raises(TaskError, match=f"puzzle: .*{match}"):
        PuzzleParams(**overrides)


def test_toml(tmp_path) -> None:
    path = tmp_path / "puzzle.toml"
    path.write_text('task = "puzzle"\nclearance = 0.0003\nhole_yaw = 0.5\n')
    t = load_task(str(path))
    assert isinstance(t, Puzzle)
    assert t.params.clearance == pytest.approx(0.0003)
    assert t.hole2world.rz == pytest.approx(0.5)


# ------------------------------------------------ Johannsmeier et al.'s protocol, shared by the
# three tasks
@pytest.mark.parametrize("name", SEED_B_TASKS)
def test_skill_starts_are_four_deterministic_poses_above_the_hole(name: str) -> None:
    t = get_task(name)
    assert isinstance(t, SkillTask)
    a = t.protocol.skill_starts(np.random.default_rng(7))
    b = t.protocol.protocol_starts("skill", 4, np.random.default_rng(7))
    assert len(a) == 4
    for s, s2 in zip(a, b, strict=True):
        np.testing.assert_array_equal(s.pos, s2.pos)
        np.testing.assert_array_equal(s.quat, s2.quat)
        rel = t.hole2world.inverse().compose(s)
        assert rel.pos[2] == pytest.approx(t.params.approach_height)
        assert np.hypot(*rel.pos[:2]) == pytest.approx(t.params.start_offset)
        assert abs(t.yaw_error(s)) <= t.params.start_yaw + 1e-12
    dirs = np.array([np.arctan2(*t.hole2world.inverse().compose(s).pos[1::-1]) for s in a])
    if t.params.start_offset > 0:  # spread evenly: four different starts
        assert len({round(float(d), 6) for d in dirs}) == 4
    c = t.protocol.skill_starts(np.random.default_rng(8))
    assert not np.allclose(a[0].pos, c[0].pos) or t.params.start_offset == 0


@pytest.mark.parametrize("name", SEED_B_TASKS)
def test_estimated_hole_has_the_taught_error(name: str) -> None:
    t = get_task(name)
    rng = np.random.default_rng(0)
    est = [t.protocol.estimated_hole(rng) for _ in range(400)]
    dxy = np.array([e.pos[:2] - t.hole2world.pos[:2] for e in est])
    assert np.std(dxy) == pytest.approx(t.params.hole_pos_sigma, rel=0.15)
    assert all(e.pos[2] == pytest.approx(t.surface_z) for e in est)
    yaw = np.array([e.rz - t.hole2world.rz for e in est])
    assert np.std(yaw) == pytest.approx(t.params.hole_yaw_sigma, rel=0.15, abs=1e-12)
    exact = t.protocol.estimated_hole(rng, pos_sigma=0.0, yaw_sigma=0.0)
    np.testing.assert_allclose(exact.pos, t.hole2world.pos)
    around = t.protocol.skill_starts(np.random.default_rng(1), around=est[0])
    rel = est[0].inverse().compose(around[0])
    assert np.hypot(*rel.pos[:2]) == pytest.approx(t.params.start_offset)
    with pytest.raises(TaskError, match="sigma"):
        t.protocol.estimated_hole(rng, pos_sigma=-1.0)


@pytest.mark.parametrize("name", SEED_B_TASKS)
def test_starts_are_free_of_the_fixture_and_teacher_starts_on_it(name: str) -> None:
    t = get_task(name)
    model = mujoco.MjModel.from_xml_string(build_scene(t))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(2)
    for s in t.protocol.protocol_starts("skill", 4, rng):
        data.qpos[:3], data.qpos[3:7] = s.pos, s.quat
        mujoco.mj_forward(model, data)
        assert data.ncon == 0
    for s in t.protocol.protocol_starts("teacher", 5, rng):
        assert s.pos[2] == pytest.approx(t.surface_z)
        assert t.lateral_error(s) == pytest.approx(t.params.demo_offset)
        data.qpos[:3], data.qpos[3:7] = s.pos + [0, 0, 1e-5], s.quat
        mujoco.mj_forward(model, data)
        assert data.ncon == 0
    with pytest.raises(TaskError, match="skill, teacher"):
        t.protocol.protocol_starts("table1", 4, rng)
    with pytest.raises(TaskError, match="positive"):
        t.protocol.protocol_starts("skill", 0, rng)


@pytest.mark.parametrize("name", SEED_B_TASKS)
def test_search_pose_and_registry(name: str) -> None:
    t = get_task(name)
    frame = Pose.from_xyz_rz(0.001, 0.0, t.surface_z, 0.3)
    state = np.array([0.001, 0.0, 0.2][: len(t.search_dims)])
    pose = t.protocol.search_pose(state, frame, height=0.001)
    assert pose.pos[2] == pytest.approx(t.surface_z + 0.001)
    assert pose.rz == pytest.approx(0.5 if t.has_rz else 0.3)
    with pytest.raises(TaskError, match="search states"):
        t.protocol.search_pose(np.zeros(5), frame)
    assert t.scene.contact.friction == t.params.friction
    assert (
        t.success_depth
        < t.hole_depth
        == pytest.approx(getattr(t.params, "hole_depth", getattr(t.params, "slot_depth", None)))
    )
    rows = [r[0] for r in t.param_table()]
    assert rows[-1] == "friction"  # the shared protocol parameters come last


@pytest.mark.parametrize("name", SEED_B_TASKS)
def test_each_start_runs_with_its_own_deliberately_deviated_hole_estimate(name: str) -> None:
    from teachfit.execution.skill_trial import peg_in_hole_setup

    t = get_task(name, start_deviation=0.001, start_offset=0.002)
    setup = peg_in_hole_setup(t, seed=4)
    assert len(setup.frames) == len(setup.starts) == 4
    for i, (start, frame) in enumerate(zip(setup.starts, setup.frames, strict=True)):
        shift = setup.task2world.inverse().compose(frame).pos
        toward = setup.task2world.inverse().compose(start).pos[:2]
        assert np.hypot(*shift[:2]) == pytest.approx(0.001) and shift[2] == pytest.approx(0)
        assert float(shift[:2] @ toward) > 0  # moved towards the start's own side
        assert setup.frame(i) is frame
    default = peg_in_hole_setup(get_task(name), seed=4)
    moved = [np.hypot(*default.task2world.inverse().compose(f).pos[:2]) for f in default.frames]
    assert moved == pytest.approx([get_task(name).params.start_deviation] * 4, abs=1e-12)
