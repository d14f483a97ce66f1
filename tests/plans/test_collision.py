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
