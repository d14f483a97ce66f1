"""The tilted search (``skills/tilt*.py``): its graph's phases on fed percepts, the node
sequence of one execution, and a pass over a sharp hole that an upright peg misses."""

import dataclasses
import math
from typing import Any

import numpy as np
import pytest

from teachfit.core.errors import SkillError
from teachfit.core.geometry import Pose, wxyz_to_rotation
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.follow import run_trajectory
from teachfit.execution.search import task_follow_config
from teachfit.robot.registry import make_robot
from teachfit.skills.follow import FollowConfig, FollowSetpoints, follow_skill
from teachfit.skills.library import get_skill
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.tilt import (
    LEAD_TIME,
    LIFT_SPEED,
    MISSES,
    TiltConfig,
    rim_lead,
    tilted_drop,
    wedge_lag,
)
from teachfit.skills.tilt_context import TiltContext, context_of
from teachfit.skills.tilt_graph import NODES
from teachfit.tasks import get_task


def test_config_checks_and_default_direction_leans_toward_the_path():
    with pytest.raises(SkillError, match="angle"):
        TiltConfig(angle=0.0)
    with pytest.raises(SkillError, match="stall_lag"):
        TiltConfig(stall_lag=-1.0)
    path = np.array([[0.0, 0.0, 0.0], [0.0, 0.02, 0.0], [0.0, 0.04, 0.0]])
    assert np.allclose(TiltConfig().unit(path), (0.0, 1.0))
    assert np.allclose(TiltConfig(direction=np.pi).unit(path), (-1.0, 0.0))
    assert np.allclose(TiltConfig().unit(np.zeros((3, 3))), (1.0, 0.0))


def test_wedge_lag_grows_with_friction_and_tilt():
    lag = wedge_lag(0.25, 0.5, 6.0, 2500.0)
    assert lag == pytest.approx(2 * 6.0 * (np.tan(0.25) + 0.5) / (1 - 0.5 * np.tan(0.25)) / 2500)
    assert wedge_lag(0.25, 0.8, 6.0, 2500.0) > lag > wedge_lag(0.1, 0.5, 6.0, 2500.0)


class _Walk:
    """A tilted search's graph fed percepts as the engine runs it each command: the active
    node's transitions (a ``chain`` target's in turn), then the active node's command."""

    def __init__(self, traj: SetpointTrajectory, tilt: TiltConfig, **follow: Any) -> None:
        self.nodes = follow_skill(traj, FollowConfig(tilt=tilt, **follow)).compile()[0]
        self.pc = Percept(Pose(np.zeros(3)), 0.01)
        self.active = self.nodes[0]
        self.active.run.enter(self.pc)

    def __call__(self, p: Any, t: float) -> MPCommand:
        pc = self.pc
        pc.p[:] = p
        pc.t = t
        for _ in self.nodes:
            fired = next((i for check, i, _ in self.active.transitions if check(pc)), None)
            if fired is None:
                break
            self.active.run.leave(pc)
            self.active = self.nodes[fired]
            self.active.run.enter(pc)
            if not self.active.chain:
                break
        cmd = MPCommand()
        self.active.run.command(pc, cmd)
        return cmd

    @property
    def node(self) -> str:
        return self.active.name

    @property
    def ctx(self) -> TiltContext:
        return context_of(self.pc)


def test_phases_tilt_drop_slide_to_the_wall_and_align():
    t = np.array([0.0, 10.0])
    pos = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])  # along +x: the rim leans +x
    traj = SetpointTrajectory.from_path(t, pos)
    tilt = TiltConfig(angle=0.2, drop_depth=5e-4, lateral_speed=0.005, stall_lag=0.002)
    walk = _Walk(traj, tilt, hold_stiffness=200.0)
    pc = walk.pc
    walk((0.0, 0.0, 0.0008), 0.1)  # resting tilted: the TCP rose
    rim = wxyz_to_rotation(pc.q_d).apply([1.0, 0.0, 0.0])
    assert walk.node == "search" and rim[2] == pytest.approx(-np.sin(0.2))  # +x rim lowest
    walk((0.010, 0.0, 0.0002), 1.0)  # sank 0.6 mm: dropped, slide on along +x
    assert walk.node == "lateral"
    cmd = walk((0.0102, 0.0, 0.0002), 1.1)
    assert pc.p_d[0] > 0.0102 and cmd.twist[0] == pytest.approx(0.005) and cmd.twist[1] == 0
    walk((0.0102, 0.0, 0.0002), 1.6)  # blocked while the set-point ran 2.5 mm on
    assert walk.node == "align"
    cmd = walk((0.0102, 0.0, 0.0), 1.85)  # half way up, held where it is
    assert np.allclose(pc.p_d[:2], (0.0102, 0.0)) and np.all(cmd.twist[:2] == 0.0)
    assert wxyz_to_rotation(pc.q_d).magnitude() == pytest.approx(0.1)
    assert np.allclose(cmd.stiffness_full[:2, :2], 200.0 * np.eye(2))
    walk((0.0102, 0.0, 0.0), 2.2)
    assert np.allclose(pc.q_d, (1.0, 0.0, 0.0, 0.0))  # upright
    walk((0.0102, 0.0, 0.0), 2.5)  # upright 0.4 s, not sinking: still waiting
    assert walk.node == "align"
    walk((0.0102, 0.0, 0.0), 2.7)  # on the edge: missed, search on, tilted
    assert walk.node == "search" and wxyz_to_rotation(pc.q_d).magnitude() == pytest.approx(0.2)
    assert np.allclose(pc.p_d[:2], (0.0102, 0.0))  # from where the part stands ...
    walk(pc.p.copy(), 2.7)  # ... back to the trajectory where it was left (t = 1 s)
    assert walk.ctx.paused == pytest.approx(2.7 - 1.0) and pc.p_d[0] < 0.0102


def _standing_still(tilt: TiltConfig) -> tuple[_Walk, Percept]:
    """A tilted search of a trajectory that stands at the origin, entered at t = 0."""
    walk = _Walk(SetpointTrajectory.from_path(np.array([0.0, 10.0]), np.zeros((2, 3))), tilt)
    return walk, walk.pc


def test_in_the_lateral_phase_the_set_point_is_free_across_the_lean():
    walk, pc = _standing_still(
        TiltConfig(angle=0.2, direction=0.0, drop_depth=5e-4, lateral_speed=0.005)
    )
    walk((0.0, 0.0, 0.0008), 0.5)  # resting tilted
    walk((0.0, 0.0, 0.0002), 0.6)  # dropped: slide along +x
    assert walk.node == "lateral"
    cmd = walk((0.0005, 0.003, 0.0002), 0.8)  # the wall pushed the rim 3 mm across
    assert walk.node == "lateral"
    assert pc.p_d[1] == pytest.approx(0.003)  # across: where the TCP is, no spring back
    assert pc.p_d[0] == pytest.approx(0.005 * 0.2)  # along: from the drop at the speed
    assert cmd.twist[0] == pytest.approx(0.005) and cmd.twist[1] == 0.0


def test_after_a_missed_align_it_retries_at_the_other_tilt_and_feels_a_drop_at_once():
    walk, pc = _standing_still(
        TiltConfig(angle=0.25, retry_angle=0.14, drop_depth=5e-4, stall_lag=0.002)
    )
    for t, z in ((0.5, 0.003), (0.6, 0.0024), (1.2, 0.0024), (1.5, 0.0), (2.4, 0.0)):
        walk((0.0, 0.0, z), t)  # rest, drop, blocked, align, upright on the edge
    assert walk.node == "search" and wxyz_to_rotation(pc.q_d).magnitude() == pytest.approx(0.14)
    walk((0.0, 0.0, -6e-4), 2.5)  # still tilting, but below the edge it stood on
    assert walk.node == "lateral"
    for t in (3.1, 3.4, 4.2):  # blocked, align, upright and not sinking: missed again
        walk((0.0, 0.0, -6e-4), t)
    assert walk.node == "search" and wxyz_to_rotation(pc.q_d).magnitude() == pytest.approx(0.25)
    again = _standing_still(TiltConfig(angle=0.25, retry_angle=0.14))[0]  # a new execution:
    assert again.ctx.full == 0.25 and again.ctx.z_floor == -np.inf  # a new context


def test_tilted_drop_is_the_deeper_of_rim_on_top_and_both_rims_inside():
    d, c, a = 0.03, 5e-4, 0.25
    assert tilted_drop(a, d, c) == pytest.approx(d * np.sin(a))  # 7.4 mm: high rim on top
    narrow = tilted_drop(0.1, d, c)  # nearly upright: the whole tip gets in, leaning on
    assert narrow == pytest.approx((d + c - d * np.cos(0.1)) / np.tan(0.1))
    assert narrow > d * np.sin(0.1)
    with pytest.raises(SkillError, match="off_depth"):
        TiltConfig(drop_depth=5e-4, off_depth=4e-4)


def test_a_drop_deeper_than_a_hole_gives_lifts_back_over_the_top_and_goes_on_upright():
    t = np.array([0.0, 10.0])
    pos = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])  # along +x: the rim leans +x
    traj = SetpointTrajectory.from_path(t, pos)
    tilt = TiltConfig(angle=0.2, drop_depth=5e-4, stall_lag=0.01, off_depth=0.008)
    walk = _Walk(traj, tilt)
    pc = walk.pc
    walk((0.0, 0.0, 0.003), 0.5)  # resting tilted
    walk((0.005, 0.0, 0.0024), 1.0)  # the low rim went over the top's edge
    assert walk.node == "lateral"
    walk((0.007, 0.0, -0.002), 1.4)  # pivoting on it, sinking: a hole gives that
    assert walk.node == "lateral"
    cmd = walk((0.018, 0.0, -0.0055), 1.8)  # 8.5 mm: deeper than any hole gives
    assert walk.node == "lift"
    assert cmd.wrench[2] == 0.0 and cmd.twist[2] == LIFT_SPEED  # no push: up, in place
    assert np.allclose(pc.p_d[:2], (0.018, 0.0))
    walk((0.018, 0.0, -0.03), 2.8)  # hanging below the set-point
    assert walk.node == "lift" and pc.p_d[2] == pytest.approx(-0.0055 + LIFT_SPEED)
    walk((0.018, 0.0, 0.0042), 3.0)  # 1.2 mm above the top: over to the trajectory
    z_held = pc.p_d[2]
    cmd = walk((0.0179, 0.0, 0.0042), 3.02)  # where it was left at 1 s: x = 10 mm
    assert 0.01 < pc.p_d[0] < 0.018 and cmd.twist[0] == -LIFT_SPEED and pc.p_d[2] == z_held
    walk((0.011, 0.0, 0.0042), 3.2)
    assert walk.node == "back" and pc.p_d[0] == pytest.approx(0.01)  # there, TCP not yet
    walk((0.0105, 0.0, 0.0042), 3.3)
    assert walk.node == "upright" and wxyz_to_rotation(pc.q_d).magnitude() == 0.0
    assert walk.ctx.paused == pytest.approx(3.3 - 1.0)
    walk((0.012, 0.0, 0.0), 3.5)  # upright on the top, lower: not a drop
    assert walk.node == "upright" and wxyz_to_rotation(pc.q_d).magnitude() == 0.0
    walk((0.031, 0.0, 0.0), 4.0)  # a reach from the edge: tilted again
    assert wxyz_to_rotation(pc.q_d).magnitude() == pytest.approx(0.2)
    walk((0.031, 0.0, 0.002), 4.5)  # settled tilted, then a hole's drop
    walk((0.031, 0.0, 0.0014), 4.6)
    assert walk.node == "lateral"


def test_with_a_lead_the_set_points_go_back_so_that_the_low_rim_follows_the_path():
    assert rim_lead(0.25, 0.03) == pytest.approx(0.015 * np.cos(0.25))
    with pytest.raises(SkillError, match="lead"):
        TiltConfig(lead=-1e-3)
    t = np.array([0.0, 10.0])
    pos = np.array([[0.0, 0.0, 0.0], [0.0, 0.1, 0.0]])  # along +y: the rim leans +y
    traj = SetpointTrajectory.from_path(t, pos)
    walk = _Walk(traj, TiltConfig(lead=0.01))
    pc = walk.pc
    walk((0.0, 0.0, 0.0), 0.0)
    assert np.allclose(pc.p_d[:2], 0.0)  # from where the part is
    walk((0.0, 0.0, 0.0), 0.5 * LEAD_TIME)
    assert np.allclose(pc.p_d[:2], (0.0, 0.005 * LEAD_TIME - 0.005))  # half way back
    walk((0.0, 0.0, 0.0), 2.0)
    assert np.allclose(pc.p_d[:2], (0.0, 0.02 - 0.01))  # the low rim on the path
    upright = FollowSetpoints(traj, FollowConfig()).compile({})
    upright.enter(pc)
    pc.t_node = 2.0
    upright.command(pc, MPCommand())
    assert np.allclose(pc.p_d[:2], (0.0, 0.02))


def test_peg2d_jam_free_tilt_is_where_the_high_rim_clears_the_near_edge():
    task = get_task("peg2d", peg_diameter=0.03, clearance=3e-4, peg_chamfer=0.0, hole_chamfer=0.0)
    r, big_r = 0.015, 0.01515
    assert task.jam_free_tilt == pytest.approx(np.arccos(r / big_r))  # 0.14 rad
    config = task_follow_config(task).tilt
    assert config.angle == 0.25 and config.retry_angle == pytest.approx(task.jam_free_tilt)
    wide = get_task("peg2d", peg_diameter=0.008, clearance=5e-4, peg_chamfer=0.0, hole_chamfer=0.0)
    assert task_follow_config(wide).tilt.retry_angle is None  # acos(4 / 4.25) > 0.25 rad
    assert config.off_depth == pytest.approx(tilted_drop(0.25, 0.03, 3e-4) + 0.002)
    assert config.lead == pytest.approx(rim_lead(0.25, 0.03))


def test_no_drop_is_felt_while_the_part_still_tilts():
    walk = _standing_still(TiltConfig())[0]
    walk((0.0, 0.0, 0.003), 0.05)  # bounced up while tilting
    walk((0.0, 0.0, 0.002), 0.25)
    walk((0.0, 0.0, 0.002), 0.35)  # settled 1 mm lower: not a drop
    assert walk.node == "search"
    walk((0.0, 0.0, 0.0014), 0.5)
    assert walk.node == "lateral"


def test_the_phases_are_the_graph_s_nodes_and_a_tilted_follow_node_is_refused():
    traj = SetpointTrajectory.from_path(np.array([0.0, 10.0]), np.zeros((2, 3)))
    skill = follow_skill(traj, FollowConfig(tilt=TiltConfig(off_depth=0.01)))
    assert tuple(n.name for n in skill.nodes) == NODES
    assert skill.start == "search" and skill.node("lateral").chain
    edges = [(tr.source, tr.target) for tr in skill.transitions]
    assert edges[:4] == [
        ("search", "lateral"),
        ("lateral", "lift"),  # checked first: off the top
        ("lateral", "search"),
        ("lateral", "align"),
    ]
    assert ("align", "search") in edges and ("upright", "search") in edges
    assert tuple(n.name for n in get_skill("tilted-search").nodes) == NODES  # skill show
    plain = follow_skill(traj, FollowConfig(tilt=TiltConfig()))  # no off_depth: no lift
    assert [n.name for n in plain.nodes] == ["search", "lateral", "align"]
    cfg = TiltConfig()  # the budget: the tour (10 s) and MISSES drops' lateral and align phases
    rounds = cfg.lateral_time + cfg.align_time
    assert cfg.extra_time == pytest.approx(MISSES * rounds) and MISSES >= 2
    budget = 10.0 + FollowConfig().settle_time + MISSES * rounds
    assert plain.error.value == pytest.approx(budget + 1.0)  # the skill's own time limit
    with pytest.raises(SkillError, match="follow_skill"):
        FollowSetpoints(traj, FollowConfig(tilt=TiltConfig())).compile({})
    with pytest.raises(SkillError, match="inside its graph"):
        skill.node("lateral").primitive.compile({}).enter(Percept(Pose(np.zeros(3)), 0.01))


@pytest.fixture(scope="module")
def sharp_pass():
    task = get_task("peg2d", peg_diameter=0.008, clearance=2e-4, peg_chamfer=0.0, hole_chamfer=0.0)
    robot = make_robot("floating", task, seed=0)
    t = np.linspace(0.0, 2.0, 40)
    xy = np.column_stack([-0.01 + 0.01 * t, np.full(t.size, 0.0015)])  # 1.5 mm off the axis
    traj = SetpointTrajectory.from_path(t, np.column_stack([xy, np.full(t.size, 0.06)]))
    return task, robot, traj, task.contact_pose(xy[0])


def test_a_tilted_pass_drops_in_where_an_upright_one_slides_over(sharp_pass):
    task, robot, traj, start = sharp_pass
    cfg = dataclasses.replace(task_follow_config(task), settle_time=0.5)
    assert cfg.tilt is not None and cfg.tilt.angle == task.search_tilt == 0.25
    tilted = run_trajectory(robot, task, traj, start, cfg)
    assert tilted.success and tilted.ground_truth_inserted
    assert [v.node for v in tilted.visits] == ["search", "lateral", "align"]  # the phases
    assert tilted.visits[0].reason.startswith("-> lateral: sank drop_depth")
    logged = [tilted.node_names[i] for i in dict.fromkeys(tilted.log.node.tolist())]
    assert logged == ["search", "lateral", "align"]  # the run log shows the active phase
    upright = run_trajectory(robot, task, traj, start, dataclasses.replace(cfg, tilt=None))
    assert not upright.success and not upright.ground_truth_inserted


def test_a_negative_ramp_time_is_an_error() -> None:
    assert TiltConfig(ramp_time=0.5).ramp_time == 0.5
    with pytest.raises(SkillError, match="ramp_time"):
        TiltConfig(ramp_time=-0.1)


def test_a_non_round_part_leans_toward_its_corner_nearest_the_path() -> None:
    corner = math.atan2(0.004, 0.006)  # a 12 x 8 mm rectangle
    path = np.array([[0.0, 0.0], [0.01, 0.001], [0.02, -0.001]])  # toward +x, a little +y
    assert np.allclose(TiltConfig().unit(path), [1.0, 0.0])  # round: along the path
    d = TiltConfig(corner=corner).unit(path)
    assert np.allclose(d, [math.cos(corner), math.sin(corner)])
    down = np.array([[0.0, 0.0], [-0.001, -0.01], [-0.002, -0.02]])  # -y, a little -x
    back = TiltConfig(corner=corner).unit(down)
    assert np.allclose(back, [-math.cos(corner), -math.sin(corner)])
