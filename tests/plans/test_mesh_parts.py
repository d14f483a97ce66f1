"""Planning assemblies from mesh task files: exact meshes, collision-free start and goal."""

from __future__ import annotations

import numpy as np
import pytest

from teachfit.core.errors import TaskError
from teachfit.plans.collision import CollisionChecker
from teachfit.plans.parts import build_assembly
from teachfit.plans.planner import MotionPlanner


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
