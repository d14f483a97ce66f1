"""Mesh-mesh collision and distance with coal."""

import numpy as np
import pytest
import trimesh

from teachfit.core.errors import PlanningError
from teachfit.plans import CollisionChecker, build_assembly, pose_from_xyz_rpy


@pytest.fixture(scope="module")
def lgroove():
    asm = build_assembly("l-groove")
    return asm, CollisionChecker(asm.moving, asm.fixed)


def test_collision_and_distance_agree(lgroove):
    asm, checker = lgroove
    assert not checker.collides(asm.goal)
    assert checker.distance(asm.start) > 0.02
    sunk = asm.goal.copy()
    sunk[2, 3] -= 0.01  # through the floor
    assert checker.collides(sunk)
    assert checker.distance(sunk) <= 0.0
    tilted = asm.goal @ pose_from_xyz_rpy(np.zeros(3), [0.0, 0.0, 30.0])  # yawed into the walls
    assert checker.collides(tilted)


def test_xyzq_hot_path_matches_matrix_query(lgroove):
    asm, checker = lgroove
    rng = np.random.default_rng(0)
    for _ in range(50):
        pos = rng.uniform(asm.bounds[0], asm.bounds[1])
        rpy = rng.uniform(-40, 40, 3)
        T = pose_from_xyz_rpy(pos, rpy)
        from scipy.spatial.transform import Rotation

        x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
        assert checker.collides_xyzq(*pos, w, x, y, z) == checker.collides(T)


def test_every_collision_check_is_counted(lgroove):
    # the planner reports n_checks as its work (and budgets attempts in it); the time per check
    # is a benchmark figure (`teachfit bench planning`), not a test
    asm, checker = lgroove
    x, y, z = asm.goal[:3, 3]
    before = checker.n_checks
    for _ in range(7):
        checker.collides_xyzq(x, y, z, 1.0, 0.0, 0.0, 0.0)
    checker.collides(asm.start)
    checker.distance(asm.start)  # a distance query is not a collision check
    assert checker.n_checks - before == 8


def test_degenerate_meshes_raise(lgroove):
    asm, _ = lgroove
    flat = trimesh.Trimesh(
        vertices=[[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]],
        faces=[[0, 1, 2], [0, 1, 3]],
        process=False,
    )
    with pytest.raises(PlanningError, match="zero-area"):
        CollisionChecker(flat, asm.fixed)
    empty = trimesh.Trimesh(vertices=np.zeros((0, 3)), faces=np.zeros((0, 3), dtype=int))
    with pytest.raises(PlanningError, match="no triangles"):
        CollisionChecker(asm.moving, empty)
    bad = asm.moving.copy()
    bad.vertices[0, 0] = np.nan
    with pytest.raises(PlanningError, match="non-finite"):
        CollisionChecker(bad, asm.fixed)
    with pytest.raises(PlanningError, match="margin"):
        CollisionChecker(asm.moving, asm.fixed, margin=-1.0)


@pytest.mark.parametrize("task", ["l-groove", "tenon"])
def test_box_checks_agree_with_the_mesh_checks(task):
    # the parametric parts are unions of boxes: the planner tests the boxes, the meshes are
    # those unions; both must call the same poses colliding (near contact included)
    asm = build_assembly(task)
    boxes = CollisionChecker.of(asm)
    meshes = CollisionChecker(asm.moving, asm.fixed)
    rng = np.random.default_rng(1)
    lo, hi = asm.bounds
    near = np.linspace(0.0, 1.0, 100)[:, None] * (asm.start[:3, 3] - asm.goal[:3, 3])
    positions = np.concatenate([rng.uniform(lo, hi, (200, 3)), asm.goal[:3, 3] + near])
    hits = 0
    for p in positions:
        T = pose_from_xyz_rpy(p, rng.normal(0.0, 4.0, 3))
        hits += boxes.collides(T)
        assert boxes.collides(T) == meshes.collides(T), p
    assert 0 < hits < len(positions)


def test_box_margin_counts_near_poses_as_colliding():
    asm = build_assembly("l-groove")
    lifted = asm.goal.copy()
    lifted[2, 3] += 0.004  # still in the cavity, free, a few mm from the floor and lip
    assert not CollisionChecker.of(asm).collides(lifted)
    gap = CollisionChecker(asm.moving, asm.fixed).distance(lifted)
    assert CollisionChecker.of(asm, margin=gap + 1e-4).collides(lifted)
    assert not CollisionChecker.of(asm, margin=gap - 1e-4).collides(lifted)


def test_bad_boxes_raise():
    asm = build_assembly("tenon")
    with pytest.raises(PlanningError, match="boxes"):
        CollisionChecker(asm.moving, asm.fixed, boxes=(np.zeros((1, 2, 3)), asm.fixed_boxes))
