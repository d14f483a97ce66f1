"""A planning assembly from a mesh task: the user's exact meshes, collided by coal.

Frames: ``G`` is the world, ``L`` the tool (TCP) frame, so a demonstration recorded on the task
(TCP poses in the world) is a sequence of ``L2G`` poses as it is. The planner collides the
exact meshes (not the convex pieces MuJoCo needs). Start: ``demo_offset`` from the hole along
its x, ``start_height`` above the entry, upright; goal: aligned at the success depth. The
sampling box spans the detection radius (plus 5 mm) around the hole axis and from the hole
bottom to ``start_height`` plus the part's length above the entry. Key poses are ranked by
``z`` (the insertion runs along the hole axis, world z) and 24 candidates are taken: with a
0.1 mm clearance only a demonstrated pose just inside the entry opens the passage, and the
demonstration passes the entry in a few samples (6 candidates found none on ``square-peg``).
"""

from __future__ import annotations

from types import MappingProxyType

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.plans.parts import Assembly, PaperResult
from teachfit.tasks.registry import load_task

#: no paper reports a user's task: zero candidates, zero times
NO_PAPER = PaperResult(candidates=0, used=(0, 0), time_s=(0.0, 0.0))


def mesh_assembly(spec: str, start_height: float = 0.01) -> Assembly:
    """The :class:`Assembly` of the mesh task file ``spec`` (see the module docstring; m)."""
    from teachfit.tasks.mesh.task import MeshTask

    task = load_task(spec)
    if not isinstance(task, MeshTask):
        raise TaskError(f'{spec} is not a mesh task file (task = "mesh")')
    cell, hole = task.cell, task.hole2world
    start = hole.compose(Pose(np.array([task.params.demo_offset, 0.0, start_height]))).matrix
    goal = hole.compose(Pose(np.array([0.0, 0.0, -task.success_depth]))).matrix
    reach = task.detection_radius + 0.005
    z0 = float(hole.pos[2])
    bounds = np.array(
        [
            [-reach, -reach, z0 - cell.fit.hole_depth],
            [reach, reach, z0 + start_height + cell.held_length],
        ]
    )
    dims = {
        "clearance_per_side": cell.fit.clearance,
        "hole_depth": cell.fit.hole_depth,
        "success_depth": task.success_depth,
        "held_length": cell.held_length,
    }
    return Assembly(
        task=task.name,
        moving=cell.held,
        fixed=cell.fixed,
        start=start,
        goal=goal,
        bounds=bounds,
        key_param="z",
        n_candidates=24,
        key_region=0.005,
        dimensions=MappingProxyType(dims),
        paper=NO_PAPER,
    )
