"""Demonstration-guided motion planning (OMPL RRT-Connect over SE(3)).

Budgets are in collision checks (``max_checks``), not seconds, so that every outcome asserted
here is a function of the seed alone and holds on a slow or loaded machine.
"""

import dataclasses
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from types import SimpleNamespace

import numpy as np
import pytest

from teachfit.core.errors import PlanningError
from teachfit.core.geometry import Pose, poses_to_array
from teachfit.plans import MotionPlanner, PlannerConfig, build_assembly, synth_demo

CHECKS = 1000  # collision checks per attempt


@pytest.fixture(scope="module")
def lgroove():
    asm = build_assembly("l-groove")
    return asm, MotionPlanner(asm, PlannerConfig(max_checks=CHECKS))


def _plan_in_fresh_process(seed: int) -> np.ndarray:
    asm = build_assembly("l-groove")
    return (
        MotionPlanner(asm, PlannerConfig(max_checks=CHECKS))
        .plan(synth_demo(asm, 0), seed=seed)
        .path
    )


def _check_path(planner, result):
    path = result.path
    assert np.allclose(path[0], planner.start, atol=1e-9)
    assert np.allclose(path[-1], planner.goal, atol=1e-9) or np.allclose(
        path[-1], planner.goal * np.r_[1, 1, 1, -1, -1, -1, -1], atol=1e-9
    )
    dense = planner.densify(path, 0.0005)
    assert not any(planner.checker.collides_xyzq(*s) for s in dense)
    # outside the planner the path is poses: the same states, the same transforms
    poses = result.poses
    assert len(poses) == len(path) and all(isinstance(p, Pose) for p in poses)
    assert np.allclose(poses_to_array(poses), path, rtol=0, atol=1e-12)
    assert np.allclose(result.L2G(), np.stack([p.matrix for p in poses]), atol=1e-12)
    dense_poses = planner.dense_poses(poses, 0.002)
    assert np.allclose(poses_to_array(dense_poses), planner.densify(path, 0.002), atol=1e-12)


def test_l_groove_with_demonstration_succeeds(lgroove):
    asm, planner = lgroove
    result = planner.plan(synth_demo(asm, 0), seed=0)
    assert result.success, result.message
    assert 1 <= result.used_key_poses <= result.candidates == 6
    assert result.collision_checks > 0 and result.attempts >= 1
    _check_path(planner, result)


def test_same_seed_same_path_whatever_ran_before(lgroove):
    asm, planner = lgroove
    demo = synth_demo(asm, 1)
    first, other, again = (planner.plan(demo, seed=s) for s in (0, 1, 0))
    assert first.success and other.success and again.success
    # exactly the same path and the same work, though another query ran in between
    assert np.array_equal(first.path, again.path)
    assert first.collision_checks == again.collision_checks
    assert first.attempts == again.attempts
    # the seed reaches OMPL's sampler (the guided plans above are straight motions, which
    # draw nothing): without a demonstration the same seed does the same work, another not
    plain = [planner.plan(None, seed=s).collision_checks for s in (0, 1, 0)]
    assert plain[0] == plain[2] != plain[1]


def test_a_worker_process_plans_the_same_path(lgroove):
    asm, planner = lgroove
    here = planner.plan(synth_demo(asm, 0), seed=3).path
    ctx = multiprocessing.get_context("spawn")  # a fresh interpreter: OMPL never seeded there
    with ProcessPoolExecutor(1, mp_context=ctx) as pool:
        there = pool.submit(_plan_in_fresh_process, 3).result()
    assert np.array_equal(here, there)


def test_tenon_with_demonstration_succeeds():
    asm = build_assembly("tenon")
    planner = MotionPlanner(asm, PlannerConfig(smooth_steps=0, max_checks=CHECKS))
    result = planner.plan(synth_demo(asm, 1), seed=1)
    assert result.success, result.message
    assert result.candidates == 11 and result.used_key_poses >= 1
    _check_path(planner, result)


def test_without_demonstration_a_short_budget_fails_cleanly(lgroove):
    _, planner = lgroove
    result = planner.plan(None, max_checks=300, seed=0)
    assert not result.success
    assert result.path.shape == (0, 7) and result.poses == ()
    assert planner.dense_poses(result.poses) == ()
    assert result.message == "no path within 300 collision checks per attempt after 1 attempt(s)"
    assert result.candidates == 0 and result.attempts == 1
    assert result.collision_checks >= 300
    # deterministic: the same failure after the same work, every time
    again = planner.plan(None, max_checks=300, seed=0)
    assert not again.success and again.collision_checks == result.collision_checks


def test_colliding_key_pose_is_replaced_by_nearby_free_pose(lgroove):
    asm, planner = lgroove
    state = planner.goal.copy()
    state[1] += 0.0025  # 1 mm into the groove's side wall
    assert planner._collides(state)
    fixed = planner.repair(state, np.random.default_rng(0))
    assert fixed is not None and not planner._collides(fixed)
    assert np.linalg.norm(fixed[:3] - state[:3]) < 0.01


def test_demonstration_of_other_parts_raises(lgroove):
    _, planner = lgroove
    demo = synth_demo(build_assembly("tenon"), 0)
    with pytest.raises(PlanningError, match="tenon"):
        planner.plan(demo)


@pytest.mark.parametrize("n", [0, 1])
def test_empty_or_single_pose_demonstration_raises(lgroove, n):
    _, planner = lgroove
    demo = SimpleNamespace(
        task="l-groove",
        t=np.arange(n, dtype=float),
        pos=np.zeros((n, 3)),
        quat=np.tile([1.0, 0, 0, 0], (n, 1)),
    )
    with pytest.raises(PlanningError, match="at least 2"):
        planner.plan(demo)


@pytest.mark.parametrize("which", ["start", "goal"])
def test_start_or_goal_in_collision_raises(lgroove, which):
    asm, _ = lgroove
    pose = asm.goal.copy()
    pose[2, 3] -= 0.01
    with pytest.raises(PlanningError, match=f"{which} pose .* in collision"):
        MotionPlanner(dataclasses.replace(asm, **{which: pose}))


def test_planner_selection_and_bad_config():
    with pytest.raises(PlanningError, match="unknown planner"):
        PlannerConfig(planner="DDRRT")
    with pytest.raises(PlanningError, match="te, resolution"):
        PlannerConfig(te=0.0)
    with pytest.raises(PlanningError, match="max_checks"):
        PlannerConfig(max_checks=0)
    asm = build_assembly("tenon")
    planner = MotionPlanner(asm, PlannerConfig(planner="RRT", smooth_steps=0, max_checks=2000))
    with pytest.raises(PlanningError, match="seed must be in"):
        planner.plan(None, seed=-1)
    result = planner.plan(synth_demo(asm, 2), seed=2)
    assert result.planner == "RRT"
    assert result.success, result.message


def test_l_groove_uses_no_more_key_poses_than_the_paper(lgroove):
    asm, planner = lgroove
    for seed in (2, 5, 38):  # 38: its evenly spaced candidates need 4 (the demonstration 2)
        result = planner.plan(synth_demo(asm, seed), seed=seed)
        assert result.success, result.message
        lo, hi = asm.paper.used
        assert result.used_key_poses <= hi
        # the straight-motion chain comes first in the ranking
        assert result.key_poses is not None and len(result.key_poses.order) == 6


@pytest.mark.parametrize(
    ("task", "overrides"),
    [("l-groove", {"clearance": 0.0005}), ("tenon", {"clearance": 0.0005})],
)
def test_tight_variants_plan_from_collision_free_demonstrations(task, overrides):
    asm = build_assembly(task, **overrides)
    demo = synth_demo(asm, 0, p_penetrate=0.0)
    assert demo.meta["n_colliding"] == 0  # the tremor stays within the clearance
    result = MotionPlanner(asm, PlannerConfig(max_checks=CHECKS)).plan(demo, seed=0)
    assert result.success, result.message
