"""Planning assemblies from mesh task files: exact meshes, collision-free start and goal."""

from __future__ import annotations

import numpy as np
import pytest

from teachfit.core.errors import PlanningError, TaskError
from teachfit.plans.collision import CollisionChecker
from teachfit.plans.planner import MotionPlanner
from teachfit.tasks.registry import build_assembly


def test_mesh_task_file_gives_exact_meshes_and_free_end_poses(mesh_examples) -> None:
    asm = build_assembly(mesh_examples["square-peg"])
    assert asm.task.endswith("square-peg.toml")
    assert len(asm.fixed.faces) == 60  # the exact plate mesh, not its 11 boxes
    MotionPlanner(asm)  # raises if the start or the goal pose is in collision
    checker = CollisionChecker(asm.moving, asm.fixed)
    off = asm.goal.copy()
    off[0, 3] += 0.0002  # 0.2 mm off the axis inside a hole with 0.1 mm per side
    assert not checker.collides(asm.goal) and checker.collides(off)
    assert np.all(asm.bounds[0] < asm.goal[:3, 3]) and np.all(asm.goal[:3, 3] < asm.bounds[1])


def test_mesh_task_takes_no_dimension_overrides(mesh_examples) -> None:
    with pytest.raises(TaskError, match="no overrides"):
        build_assembly(mesh_examples["usb"], clearance=0.001)


def test_planner_inserts_along_the_axis_with_and_without_demo(mesh_examples) -> None:
    asm = build_assembly(mesh_examples["square-peg"])
    mp = MotionPlanner(asm)
    result = mp.plan(None, seed=0)
    assert result.success and mp.verify(result.path)
    # the path passes the approach pose above the entry and ends inside the hole
    tips = result.path[:, :3]
    assert np.allclose(tips[-1], asm.goal[:3, 3])
    assert np.any(np.linalg.norm(tips - asm.approach[:3, 3], axis=1) < 1e-9)


def test_approach_that_collides_is_an_error(mesh_examples) -> None:
    import dataclasses

    asm = build_assembly(mesh_examples["square-peg"])
    bad = asm.approach.copy()
    bad[0, 3] += 0.0003  # above the entry but 0.3 mm off the axis: the insertion hits the edge
    with pytest.raises(PlanningError, match="straight insertion"):
        MotionPlanner(dataclasses.replace(asm, approach=bad))
