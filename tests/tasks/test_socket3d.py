"""The ``socket3d`` task: geometry, ground truth, protocols, parameter validation."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.spatial import ConvexHull

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolRobot, build_scene
from teachfit.tasks import Socket3D, Socket3DParams, get_task
from teachfit.tasks.scene.socket_pieces import valley_wedge

STIFF = [300, 300, 300, 50, 50, 50]


@pytest.fixture(scope="module")
def task() -> Socket3D:
    t = get_task("socket3d")
    assert isinstance(t, Socket3D)
    return t


@pytest.fixture(scope="module")
def robot(task: Socket3D) -> FloatingToolRobot:
    return FloatingToolRobot(task)


def push(robot: FloatingToolRobot, x: float, y: float, rz: float, steps: int = 1200) -> Pose:
    """Start 2 mm above the floor at (x, y, rz) and push down with a soft impedance."""
    start = Pose.from_xyz_rz(x, y, robot.task.surface_z + 0.002, rz)
    robot.reset(start)
    robot.command(ImpedanceCommand(pos=start.pos - [0, 0, 0.03], quat=start.quat, stiffness=STIFF))
    return robot.step(steps).pose


def test_scene_compiles_with_convex_pieces(task: Socket3D) -> None:
    model = mujoco.MjModel.from_xml_string(build_scene(task))
    names = [model.geom(i).name for i in range(model.ngeom)]
    p = task.params
    assert sum(n.startswith("valley_") for n in names) == 2 * p.n_wedges
    assert sum(n.startswith("recess_wall_") for n in names) == p.n_wall_sectors
    assert {"pin_small", "pin_large", "plug_body", "socket_base"} <= set(names)
    part = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "held_part")
    assert model.body_mass[part] == pytest.approx(0.1)


def test_registered() -> None:
    t = get_task("socket3d", clearance_small=0.0002)
    assert t.search_dims == ("x", "y", "rz")
    assert t.params.clearance_small == 0.0002


@pytest.mark.parametrize("rz", [0.0, np.pi])
def test_aligned_plug_enters(robot: FloatingToolRobot, task: Socket3D, rz: float) -> None:
    pose = push(robot, 0.0, 0.0, rz)
    assert task.insertion_depth(pose) > task.success_depth
    assert task.ground_truth_inserted(pose)


@pytest.mark.parametrize("deg", [20.0, 90.0])
def test_rotated_plug_is_blocked(robot: FloatingToolRobot, task: Socket3D, deg: float) -> None:
    pose = push(robot, 0.0, 0.0, np.deg2rad(deg))
    assert task.insertion_depth(pose) < 0.0  # pins stay above the hole entries
    assert not task.ground_truth_inserted(pose)


@pytest.mark.parametrize("offset", [(0.003, 0.0), (0.0, 0.003), (-0.002, 0.002)])
def test_valleys_guide_an_offset_plug_in(
    robot: FloatingToolRobot, task: Socket3D, offset: tuple[float, float]
) -> None:
    pose = push(robot, *offset, 0.0)
    assert task.ground_truth_inserted(pose)


@pytest.mark.parametrize("offset", [(0.003, 0.0), (0.0, 0.003)])
def test_offset_plug_is_blocked_without_valleys(offset: tuple[float, float]) -> None:
    flat = get_task("socket3d", valley_depth=0.0)
    assert flat.hole2world.pos[2] == flat.surface_z
    pose = push(FloatingToolRobot(flat), *offset, 0.0)
    assert abs(flat.insertion_depth(pose)) < 1e-4  # resting on the flat floor
    assert not flat.ground_truth_inserted(pose)


def test_ground_truth_inserted_needs_both_pins(task: Socket3D) -> None:
    z = task.hole2world.pos[2] - 0.012
    assert task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z, 0.0))
    assert task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z, np.pi))  # pins swap holes
    assert not task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z, 0.1))  # one pin 1 mm off
    assert not task.ground_truth_inserted(Pose.from_xyz_rz(0.0012, 0, z, 0.0))
    assert not task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z + 0.004, 0.0))  # too shallow


def test_search_pose_composes_rz(task: Socket3D) -> None:
    frame = Pose.from_xyz_rz(0.001, 0.002, task.surface_z, 0.3)
    pose = task.protocol.search_pose(np.array([0.001, 0.0, 0.2]), frame, height=0.001)
    assert pose.rz == pytest.approx(0.5)
    np.testing.assert_allclose(
        pose.pos, [0.001 + 0.001 * np.cos(0.3), 0.002 + 0.001 * np.sin(0.3), task.surface_z + 1e-3]
    )
    with pytest.raises(TaskError, match="x, y, rz"):
        task.protocol.search_pose(np.zeros(2), frame)


@pytest.mark.parametrize("protocol", ["teacher", "table3"])
def test_protocol_starts_inside_recess(task: Socket3D, protocol: str) -> None:
    p = task.params
    starts = task.protocol.protocol_starts(protocol, 15, np.random.default_rng(3))
    assert len(starts) == 15
    model = mujoco.MjModel.from_xml_string(build_scene(task))
    data = mujoco.MjData(model)
    for s in starts:
        r = float(np.hypot(*s.pos[:2]))
        assert r + p.body_diameter / 2 < p.recess_diameter / 2  # body clear of the wall
        assert s.pos[2] == pytest.approx(task.surface_z)
        assert abs(s.rz) <= p.start_rz
        assert s.pos[1] >= 0.0  # the socket's upper half
        data.qpos[:3], data.qpos[3:7] = s.pos + [0, 0, 1e-5], s.quat
        mujoco.mj_forward(model, data)
        assert data.ncon == 0  # no overlap with the wall or the floor
    if protocol == "teacher":
        gap = p.recess_diameter / 2 - p.body_diameter / 2 - np.hypot(*starts[0].pos[:2])
        assert gap == pytest.approx(p.start_wall_gap)
        tips = np.array([task.pin_tips(s)[:, :2] for s in starts])
        holes = task.hole_xy
        dist = np.linalg.norm(tips[:, :, None, :] - holes[None, None], axis=-1)
        assert dist.min() >= p.valley_radius  # worst case: no pin starts in a valley


def test_bad_protocol(task: Socket3D) -> None:
    with pytest.raises(TaskError, match="table3"):
        task.protocol.protocol_starts("table1", 3, np.random.default_rng(0))
    with pytest.raises(TaskError, match="positive"):
        task.protocol.protocol_starts("table3", 0, np.random.default_rng(0))


def test_flat_wedges_tile_the_square_minus_the_hole() -> None:
    k, r, hw = 16, 0.0022, 0.0095
    vols = [
        ConvexHull(
            valley_wedge(
                (0.0, 0.0),
                2 * np.pi * i / k,
                2 * np.pi * (i + 1) / k,
                r,
                hw,
                0.0,
                0.01,
                0.01,
                0.005,
            )
        ).volume
        for i in range(k)
    ]
    hole_area = k * r**2 * np.tan(np.pi / k)  # polygon circumscribing the hole circle
    assert sum(vols) == pytest.approx((4 * hw**2 - hole_area) * 0.01, rel=1e-9)


def test_valley_wedge_heights() -> None:
    v = valley_wedge((0.0, 0.0), -np.pi / 16, np.pi / 16, 0.002, 0.0095, 0.0, 0.0075, 0.01, 0.006)
    at_hole = np.isclose(v[:, 0], 0.002)
    assert np.allclose(v[at_hole & (v[:, 2] > 0), 2], 0.0075)  # the hole edge: valley bottom
    assert np.allclose(v[v[:, 0] >= 0.006 - 1e-12, 2].max(), 0.01)  # flat floor outside
    assert v[:, 2].max() == pytest.approx(0.01)


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"clearance_small": 0.0}, "clearance_small must be > 0"),
        ({"clearance_large": 0.0003}, "clearance_large"),
        ({"clearance_large": 0.005, "clearance_small": 0.004}, "smaller than the pin"),
        ({"valley_depth": -0.001}, "valley_depth must be >= 0"),
        ({"valley_radius": 0.002}, "valley_radius"),
        ({"valley_radius": 0.0095}, "valley_radius"),
        ({"success_depth": 0.017}, "deeper than the holes"),
        ({"hole_depth": 0.0165}, "bottom out"),
        ({"pin_spacing": 0.005}, "between holes"),
        ({"body_diameter": 0.020}, "cover both pins"),
        ({"body_diameter": 0.043}, "play"),
        ({"recess_depth": 0.019}, "recess_depth"),
        ({"recess_diameter": 0.030, "body_diameter": 0.024}, "outer radius"),
        ({"floor_height": 0.015}, "floor_height"),
        ({"n_wedges": 4}, "n_wedges"),
        ({"n_wall_sectors": 6}, "n_wall_sectors"),
        ({"start_rz": 2.0}, "start_rz"),
        ({"pin_tip_radius": 0.002}, "pin_tip_radius"),
    ],
)
def test_impossible_parameters(overrides: dict[str, float], match: str) -> None:
    with pytest.raises(TaskError, match=match):
        Socket3DParams(**overrides)


def test_wrong_params_type() -> None:
    with pytest.raises(TaskError, match="Socket3DParams"):
        Socket3D(object())
    with pytest.raises(TaskError, match="unknown socket3d"):
        get_task("socket3d", pin_width=0.004)
