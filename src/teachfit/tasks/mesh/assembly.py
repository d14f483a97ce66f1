"""A planning assembly from a mesh task: the user's exact meshes, collided by coal.

Frames: ``G`` is the world, ``L`` the tool (TCP) frame, so a demonstration recorded on the task
(TCP poses in the world) is a sequence of ``L2G`` poses as it is. The planner collides the
exact meshes (not the convex pieces MuJoCo needs). Start: ``demo_offset`` from the hole along
its x, ``start_height`` above the entry, upright; goal: aligned at the success depth, reached
by the straight insertion along the hole axis from the approach pose (aligned, tip
:data:`APPROACH_HEIGHT` above the entry; see :class:`MeshAssembly`). The sampling box spans the
detection radius (plus 5 mm) around the hole axis and from the hole bottom to
``start_height`` plus the part's length above the entry. Key poses are ranked by ``z`` (the
insertion runs along the hole axis, world z), 24 candidates; without the approach pose the
demonstration's few samples inside the 0.1 mm entry seldom opened the passage (6/20 with
them on ``square-peg``, none without a demonstration).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.tasks.base import read_task_toml
from teachfit.tasks.mesh.task import load_mesh_task
from teachfit.tasks.parts import Assembly, PaperResult

#: no paper reports a user's task: zero candidates, zero times
NO_PAPER = PaperResult(candidates=0, used=(0, 0), time_s=(0.0, 0.0))
#: height of the approach pose's tip above the hole entry (m)
APPROACH_HEIGHT = 2e-4


@dataclass(frozen=True, eq=False)
class MeshAssembly(Assembly):
    """An :class:`Assembly` whose goal is reached by a straight insertion from ``approach``
    ((4, 4) ``L2G``: the part aligned with the hole, its tip just above the entry).

    The task file declares the insertion axis and the task's cell checks prove the aligned
    part enters straight along it, so the planner need not find the 0.1-0.2 mm passage by
    sampling: RRT-Connect grows a tree into such a passage only by chance (its extensions
    toward uniform samples run almost always across the axis, into the walls).
    """

    approach: np.ndarray | None = None


def mesh_assembly(spec: str, start_height: float = 0.01) -> Assembly:
    """The :class:`Assembly` of the mesh task file ``spec`` (see the module docstring; m)."""
    if read_task_toml(Path(spec)).get("task") != "mesh":
        raise TaskError(f'{spec} is not a mesh task file (task = "mesh")')
    task = load_mesh_task(spec)
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
    approach = hole.compose(Pose(np.array([0.0, 0.0, APPROACH_HEIGHT]))).matrix
    return MeshAssembly(
        approach=approach,
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
