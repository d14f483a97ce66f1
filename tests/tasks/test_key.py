"""The ``key`` task: a grooved blade into a narrow warded keyway."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from scipy.spatial import ConvexHull

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolRobot, build_scene
from teachfit.tasks import Key, KeyParams, get_task
from teachfit.tasks.scene.prism_hole import KeyScene
from teachfit.tasks.scene.prisms import beyond_edge_block, chamfered_block, rectangle

STIFF = [300, 300, 300, 50, 50, 50]


@pytest.fixture(scope="module")
def task() -> Key:
    t = get_task("key")
    assert isinstance(t, Key)
    return t


@pytest.fixture(scope="module")
def robot(task: Key) -> FloatingToolRobot:
    return FloatingToolRobot(task)


def push(robot: FloatingToolRobot, x: float, y: float, rz: float, steps: int = 800) -> Pose:
    """Start 2 mm above the entry at (x, y, rz) in the hole frame and push down softly."""
    start = robot.task.hole2world.compose(Pose.from_xyz_rz(x, y, 0.002, rz))
    robot.reset(start)
    robot.command(ImpedanceCommand(pos=start.pos - [0, 0, 0.03], quat=start.quat, stiffness=STIFF))
    return robot.step(steps).pose


def test_scene_is_four_chamfered_walls_and_two_wards(task: Key) -> None:
    model = mujoco.MjModel.from_xml_string(build_scene(task))
    names = {model.geom(i).name for i in range(model.ngeom)}
    walls = {f"slot_wall_{s}" for s in ("east", "west", "north", "south")}
    wards = {"slot_ward_ne", "slot_ward_sw", "key_blade_west", "key_blade_east"}
    assert walls | wards | {"fixture_base", "key_bow"} <= names
    plain = mujoco.MjModel.from_xml_string(build_scene(get_task("key", ward_depth=0.0)))
    assert "key_blade" in {plain.geom(i).name for i in range(plain.ngeom)}


def test_blade_profile_is_the_keyway_less_its_clearance(task: Key) -> None:
    # Z-shaped profile: full thickness in the middle, a ward_depth groove on the north face
    # east of it and on the south face west of it; each ward stands clearance / 2 off
    p = task.params
    west, east = (poly for _, poly in task.blade_pieces())
    assert west[:, 1].max() == pytest.approx(p.blade_thickness / 2)
    assert west[:, 1].min() == pytest.approx(-p.blade_thickness / 2 + p.ward_depth)
    assert east[:, 0].max() == pytest.approx(p.blade_width / 2)
    assert east[:, 1].max() == pytest.approx(p.blade_thickness / 2 - p.ward_depth)
    ne = dict(KeyScene(task).hole_wards(0.0, 0.01))["slot_ward_ne"]
    assert ne[:, 1].min() - east[:, 1].max() == pytest.approx(p.clearance / 2)
    assert ne[:, 0].min() - west[:, 0].max() == pytest.approx(p.clearance / 2)


def test_chamfered_block_lowers_two_edges() -> None:
    # a 1 x 1 x 1 cube with 0.2 chamfers along two adjacent edges: two prisms of 0.02 and
    # their 0.2^3 / 3 corner pyramid counted once
    edges = [(np.array([0.0, 1.0]), -0.5), (np.array([1.0, 0.0]), -0.5)]
    v = chamfered_block(rectangle(0.5, 0.5), edges, 0.0, 1.0, 0.2)
    assert ConvexHull(v).volume == pytest.approx(1 - 2 * 0.02 + 0.2**3 / 3, rel=1e-9)
    assert v[np.isclose(v[:, 0], -0.5), 2].max() == pytest.approx(0.8)
    with pytest.raises(ValueError, match="empty"):
        chamfered_block(rectangle(0.5, 0.5), edges, 0.0, 1.0, 2.0)


def test_chamfered_walls_leave_the_slot_open() -> None:
    # four pieces over a 2 x 2 cm plate around a 7.3 x 2.3 mm slot, 1 cm tall, no chamfer:
    # their union is the plate minus the slot; by inclusion-exclusion the corner overlaps count
    hx, hy, hw, h = 0.00365, 0.00115, 0.01, 0.01
    sides = [((1.0, 0.0), hx), ((-1.0, 0.0), hx), ((0.0, 1.0), hy), ((0.0, -1.0), hy)]
    vols = [
        ConvexHull(beyond_edge_block(rectangle(hw, hw), np.array(n), d, 0.0, h)).volume
        for n, d in sides
    ]
    overlaps = 4 * (hw - hx) * (hw - hy) * h
    assert sum(vols) - overlaps == pytest.approx((4 * hw * hw - 4 * hx * hy) * h, rel=1e-9)
    v = beyond_edge_block(rectangle(hw, hw), np.array([0.0, 1.0]), hy, 0.0, h, chamfer=0.0008)
    assert v[np.isclose(v[:, 1], hy), 2].max() == pytest.approx(h - 0.0008)  # chamfer bottom
    assert v[:, 2].max() == pytest.approx(h)


@pytest.mark.parametrize("rz", [0.0, Key.rz_period])  # the declared symmetry, checked by pushing
def test_aligned_key_enters(robot, task, rz) -> None:
    pose = push(robot, 0.0, 0.0, rz)
    assert task.insertion_depth(pose) > task.params.slot_depth - 2e-4
    assert task.ground_truth_inserted(pose)


# the wards, not the 0.8 mm entry chamfer, set the lateral capture: within clearance / 2 plus
# the blade's chamfer the chamfers guide the blade in; a plain slot takes 1 mm
@pytest.mark.parametrize("offset", [(0.0003, 0.0), (-0.0003, 0.0), (0.0, 0.0005), (0.0, -0.0005)])
def test_chamfers_guide_the_blade_in_within_the_capture(robot, task, offset) -> None:
    assert task.ground_truth_inserted(push(robot, *offset, 0.0))


@pytest.mark.parametrize("offset", [(0.0007, 0.0), (-0.0007, 0.0), (0.0, 0.0008), (0.0, -0.0008)])
def test_wards_block_a_blade_beyond_the_capture(robot, task, offset) -> None:
    pose = push(robot, *offset, 0.0)
    assert task.insertion_depth(pose) < task.params.slot_chamfer
    assert not task.ground_truth_inserted(pose)


def test_plain_slot_guides_a_1mm_offset_in() -> None:
    plain = FloatingToolRobot(get_task("key", ward_depth=0.0))
    assert plain.task.ground_truth_inserted(push(plain, 0.001, 0.0, 0.0))
    assert plain.task.ground_truth_inserted(push(plain, 0.0, -0.001, 0.0))


def test_key_fixes_the_tilt_and_drops_to_the_chamfer_bottom(task: Key) -> None:
    p = task.params
    assert task.skill_fixed == {"tilt": p.fixed_tilt}
    lift = p.blade_width / 2 * np.sin(p.fixed_tilt)
    assert task.skill_context["drop_depth"] == pytest.approx(p.slot_chamfer - lift)


@pytest.mark.parametrize("offset", [(0.0025, 0.0), (0.0, 0.0025), (-0.002, 0.002)])
def test_offset_key_is_blocked(robot, task, offset) -> None:
    pose = push(robot, *offset, 0.0)
    assert task.insertion_depth(pose) < 2e-4  # rests on the lock face
    assert not task.ground_truth_inserted(pose)


# half the declared symmetry period is blocked: rz_period is the smallest symmetry
@pytest.mark.parametrize("deg", [5.0, 25.0, float(np.rad2deg(Key.rz_period / 2))])
def test_rotated_key_is_blocked(robot, task, deg) -> None:
    pose = push(robot, 0.0, 0.0, np.deg2rad(deg))
    assert task.insertion_depth(pose) < task.params.slot_chamfer + 0.001  # in the chamfer at most
    assert not task.ground_truth_inserted(pose)


def test_ground_truth_inserted_with_symmetry(task: Key) -> None:
    z = task.surface_z - 0.015
    assert task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z, np.pi))
    assert not task.ground_truth_inserted(Pose.from_xyz_rz(0, 0, z, np.pi / 2))
    assert not task.ground_truth_inserted(Pose.from_xyz_rz(0.0006, 0, z, 0.0))
    assert task.slot_half_size == pytest.approx((0.00365, 0.00115))


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"clearance": 0.0}, "clearance must be > 0"),
        ({"clearance": 0.003}, "no tight fit"),
        ({"blade_thickness": 0.008}, "flat blade"),
        ({"blade_chamfer": 0.001}, "blade_chamfer"),
        ({"slot_chamfer": -0.001}, "slot_chamfer"),
        ({"block_half_width": 0.006, "demo_offset": 0.001}, "rim"),
        ({"slot_depth": 0.039}, "slot bottom"),
        ({"success_depth": 0.021}, "deeper than the slot"),
        ({"blade_length": 0.0205}, "bow stays above"),
        ({"bow_width": 0.005}, "bow"),
        ({"ward_depth": 0.001}, "ward_depth"),
        ({"blade_chamfer": 0.0008}, "grooved blade"),
        ({"profile_middle": 0.0065}, "profile_middle"),
        ({"demo_offset": 0.018}, "off the lock face"),
        ({"friction": -0.1}, "friction"),
    ],
)
def test_impossible_parameters(overrides, match) -> None:
    with pytest.raises(TaskError, match=f"key: .*{match}"):
        KeyParams(**overrides)


@pytest.mark.parametrize("name", ["key", "puzzle"])
def test_the_rotational_amplitude_is_bounded_by_the_yaw_play(name: str) -> None:
    task = get_task(name)
    play = task.params.clearance / task.yaw_lever
    assert task.yaw_play == pytest.approx(play)
    assert task.skill_domains == {"a_r": (0.0, pytest.approx(play))}
    assert get_task(name, a_r_max=0.1).skill_domains == {"a_r": (0.0, 0.1)}
