"""Motion planning guided by demonstrated key poses (docs/methods.md, Wang et al. 2019).

The parts planned for are tasks (:mod:`teachfit.tasks.parts`, their assemblies from
:func:`teachfit.tasks.registry.build_assembly`, re-exported here); mesh-mesh collision
(:mod:`.collision`), synthetic demonstrations (:mod:`.synth`), key-pose ranking
(:mod:`.keyposes`) and the planner loop (:mod:`.planner`, with its values in :mod:`.plan_types`
and the OMPL boundary in :mod:`.ompl_space`). Poses are ``L2G``: the moving part ``L`` in the fixed
part's frame ``G``.
"""

from teachfit.plans.collision import CollisionChecker, pose_to_matrix
from teachfit.plans.keyposes import PARAMS, KeyPoses, pose_parameters, rank_key_poses
from teachfit.plans.planner import (
    PLANNERS,
    MotionPlanner,
    PlannerConfig,
    PlanResult,
    matrix_to_state,
    seed_ompl,
)
from teachfit.plans.synth import nominal_keyframes, synth_demo
from teachfit.tasks.parts import (
    PARTS,
    Assembly,
    LGrooveParams,
    PaperResult,
    TenonParams,
    pose_from_xyz_rpy,
)
from teachfit.tasks.registry import build_assembly

__all__ = [
    "PARAMS",
    "PARTS",
    "PLANNERS",
    "Assembly",
    "CollisionChecker",
    "KeyPoses",
    "LGrooveParams",
    "MotionPlanner",
    "PaperResult",
    "PlanResult",
    "PlannerConfig",
    "TenonParams",
    "build_assembly",
    "matrix_to_state",
    "nominal_keyframes",
    "pose_from_xyz_rpy",
    "pose_parameters",
    "pose_to_matrix",
    "rank_key_poses",
    "seed_ompl",
    "synth_demo",
]
