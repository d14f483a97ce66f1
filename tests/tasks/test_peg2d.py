import mujoco
import numpy as np
import pytest

from teachfit.core.errors import TaskError
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolRobot, build_scene
from teachfit.tasks import Peg2D, Peg2DParams, get_task, load_task


def push_down(task, offset):
    robot = FloatingToolRobot(task)
    start = task.contact_pose([offset, 0.0]).translated([0, 0, 0.002])
    robot.reset(start)
    robot.command(
        ImpedanceCommand(pos=start.pos - [0, 0, 0.03], stiffness=[300, 300, 300, 50, 50, 50])
    )
    return robot.step(1200)


@pytest.mark.parametrize("clearance", [0.0005, 0.0002])
def test_peg_enters_when_aligned_and_is_blocked_1mm_off(clearance):
    task = get_task("peg2d", clearance=clearance, peg_chamfer=0.0, hole_chamfer=0.0)
    aligned = push_down(task, 0.0)
    assert task.ground_truth_inserted(aligned.pose)
    assert task.insertion_depth(aligned.pose) > 0.019  # reaches the bottom (20 mm)
    off = push_down(task, 0.001)
    assert not task.ground_truth_inserted(off.pose)
    assert abs(task.insertion_depth(off.pose)) < 2e-4  # rests on the surface
    assert off.wrench[2] > 5.0  # and the surface pushes back


def test_chamfers_guide_a_1mm_offset_in():
    task = get_task("peg2d")  # default chamfers 1 mm (peg) and 0.5 mm (hole)
    assert task.ground_truth_inserted(push_down(task, 0.001).pose)


def test_impossible_parameters_are_named():
    with pytest.raises(TaskError, match="clearance"):
        Peg2DParams(clearance=0.03)
    with pytest.raises(TaskError, match="success_depth"):
        Peg2DParams(success_depth=0.05)
    with pytest.raises(TaskError, match="hole_depth"):
        Peg2DParams(hole_depth=-0.01)
    with pytest.raises(TaskError, match="unknown"):
        get_task("peg2d", peg_colour=1)
    with pytest.raises(TaskError, match="built-in"):
        get_task("nope")


def test_scene_compiles_with_convex_sectors():
    task = Peg2D(Peg2DParams(n_sectors=16))
    model = mujoco.MjModel.from_xml_string(build_scene(task))
    names = [model.geom(i).name for i in range(model.ngeom)]
    assert sum(n.startswith("hole_wall_") for n in names) == 16
    assert model.opt.timestep == pytest.approx(0.001)


def test_toml_round_trip(tmp_path):
    path = tmp_path / "task.toml"
    path.write_text('task = "peg2d"\nclearance = 0.0002\nhole_depth = 0.025\n')
    task = load_task(str(path))
    assert task.params.clearance == pytest.approx(0.0002)
    assert task.params.hole_depth == pytest.approx(0.025)
    path.write_text('task = "peg2d"\nclearence = 0.0002\n')
    with pytest.raises(TaskError, match="clearence"):
        load_task(str(path))


def test_table1_starts_lie_in_a_3cm_circle_halfway():
    task = Peg2D()
    rng = np.random.default_rng(0)
    demo_start = task.contact_pose([0.03, 0.0])
    starts = task.protocol.protocol_starts("table1", 200, rng, demo_start)
    xy = np.array([s.pos[:2] for s in starts])
    centre = np.array([0.015, 0.0])
    assert np.all(np.linalg.norm(xy - centre, axis=1) <= 0.015 + 1e-12)
    assert np.allclose([s.pos[2] for s in starts], task.surface_z)
    with pytest.raises(TaskError):
        task.protocol.protocol_starts("table9", 3, rng)


def test_friction_parameter_reaches_the_scene():
    from teachfit.robot.floating import build_scene
    from teachfit.tasks.registry import get_task

    xml = build_scene(get_task("peg2d", friction=0.7))
    assert 'friction="0.7 ' in xml and 'friction="0.3 ' not in xml


def test_search_follower_hints_follow_friction_and_chamfers():
    default = get_task("peg2d")
    assert default.stiffness_scale == 1.0  # the default cell's follower is unchanged
    assert get_task("peg2d", friction=0.2).stiffness_scale == 1.0
    assert get_task("peg2d", friction=0.8).stiffness_scale == pytest.approx(0.8 / 0.3)
    # the hold comes once the tip is below the hole's chamfer: short of the chamfers' depth
    assert default.search_hold_depth == pytest.approx(0.001)
    assert default.search_hold_depth < default.hold_depth
    sharp = get_task("peg2d", peg_chamfer=0.0, hole_chamfer=0.0)
    assert sharp.search_hold_depth == pytest.approx(0.0005)
