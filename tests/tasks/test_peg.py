"""The ``peg`` task: a chamfered aluminium peg into a hole with no walls around it."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose, rotation_to_wxyz
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolRobot, build_scene
from teachfit.tasks import AluminiumPeg, AluminiumPegParams, get_task


@pytest.fixture(scope="module")
def task() -> AluminiumPeg:
    t = get_task("peg")
    assert isinstance(t, AluminiumPeg)
    return t


@pytest.fixture(scope="module")
def robot(task: AluminiumPeg) -> FloatingToolRobot:
    return FloatingToolRobot(task)


def push(
    robot: FloatingToolRobot,
    x: float,
    *,
    shove: float = 0.0,
    tilt_deg: float = 0.0,
    rot_stiffness: float = 50.0,
    steps: int = 800,
) -> Pose:
    """Start 2 mm above the entry, ``x`` off the axis and tilted about y; push down (and +x)."""
    quat = rotation_to_wxyz(Rotation.from_euler("y", np.deg2rad(tilt_deg)))
    start = Pose(robot.task.hole2world.pos + [x, 0.0, 0.002], quat)
    robot.reset(start)
    stiff = [300, 300, 300] + [rot_stiffness] * 3
    robot.command(ImpedanceCommand(pos=start.pos + [shove, 0, -0.03], quat=quat, stiffness=stiff))
    return robot.step(steps).pose


def test_scene_is_a_free_standing_boss(task: AluminiumPeg) -> None:
    model = mujoco.MjModel.from_xml_string(build_scene(task))
    names = [model.geom(i).name for i in range(model.ngeom)]
    assert sum(n.startswith("hole_wall_") for n in names) == task.params.n_sectors
    assert {"fixture_base", "boss_core", "peg"} <= set(names)
    assert task.search_dims == ("x", "y")
    assert task.surface_z == pytest.approx(0.05)
    part = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "held_part")
    assert model.body_mass[part] == pytest.approx(2700 * np.pi * 0.008**2 * 0.06)  # aluminium


@pytest.mark.parametrize("x", [0.0, 0.0005])  # 0.5 mm chamfer + 0.15 mm clearance
def test_aligned_or_chamfer_guided_peg_enters(robot, task, x) -> None:
    pose = push(robot, x)
    assert task.insertion_depth(pose) > task.params.hole_depth - 2e-4
    assert task.ground_truth_inserted(pose)


@pytest.mark.parametrize("x", [0.002, -0.002])
def test_peg_2mm_off_is_blocked_on_the_rim(robot, task, x) -> None:
    pose = push(robot, x)
    assert abs(task.insertion_depth(pose)) < 2e-4
    assert not task.ground_truth_inserted(pose)


def test_peg_beside_the_boss_is_deep_but_not_inserted(robot, task) -> None:
    pose = push(robot, 0.022)  # clear of the 12 mm boss: nothing stops it
    assert task.insertion_depth(pose) > task.success_depth
    assert not task.ground_truth_inserted(pose)


def test_peg_slides_off_the_wall_less_hole(robot, task) -> None:
    pose = push(robot, 0.006, shove=0.03)  # pushed down and sideways from the boss top
    assert task.lateral_error(pose) > task.params.boss_diameter / 2
    assert task.insertion_depth(pose) > 0.01  # below the boss top, beside it
    assert not task.ground_truth_inserted(pose)


def test_stiffly_tilted_peg_jams_compliant_one_enters(robot, task) -> None:
    stuck = push(robot, 0.0, tilt_deg=3.0, steps=1000)
    assert 0.002 < task.insertion_depth(stuck) < task.success_depth  # wedged part-way in
    assert task.tilt(stuck) > np.deg2rad(2.0)
    assert not task.ground_truth_inserted(stuck)
    free = push(robot, 0.0, tilt_deg=3.0, rot_stiffness=0.5, steps=1500)
    assert task.ground_truth_inserted(free)
    assert task.tilt(free) < np.deg2rad(1.0)


def test_ground_truth_inserted_needs_the_axis(task: AluminiumPeg) -> None:
    z = task.surface_z - 0.02
    assert task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z, 1.0))  # round: any yaw
    assert not task.ground_truth_inserted(Pose.from_xyz_rz(0.001, 0, z))
    assert task.overhang_offset == pytest.approx(0.004)


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"clearance": 0.0}, "clearance must be > 0"),
        ({"clearance": 0.005}, "no tight fit"),
        ({"peg_chamfer": 0.008}, "peg_chamfer"),
        ({"boss_diameter": 0.0175, "demo_offset": 0.0005}, "wall"),
        ({"hole_chamfer": 0.0035}, "wall"),
        ({"hole_depth": 0.039}, "hole bottom"),
        ({"success_depth": 0.03}, "deeper than the hole"),
        ({"peg_length": 0.02}, "peg_length"),
        ({"base_half_width": 0.02}, "beside the boss"),
        ({"demo_offset": 0.005}, "off the boss top"),
        ({"n_sectors": 4}, "n_sectors"),
    ],
)
def test_impossible_parameters(overrides, match) -> None:
    with pytest.raises(TaskError, match=f"peg: .*{match}"):
        AluminiumPegParams(**overrides)
