"""A planned L-into-groove or tenon path (Wang et al. 2019) executed in contact, the last step a
skill.

Wang et al. 2019 executed its plans on the robot open loop and failed when vision was off. Here the
plan (:class:`~teachfit.plans.planner.MotionPlanner`, guided by a demonstration) is executed by the
impedance-controlled floating robot holding the part in MuJoCo physics
(:class:`~teachfit.tasks.geometry.parts_cell.PartsCell`), with the fixed part where it truly is --
its captured pose off by a sampled capture error (:func:`capture_error`) -- while the robot
believes the captured pose:

- ``"joined"``: the path is tracked by the impedance controller (stiffness :data:`TRACK`;
  compliant tracking was measured worse here), then the final insertion is a skill: ``seat`` pushes
  the part along the insertion direction; the L is seated when the groove's end wall resists
  within the capture tolerance of the believed goal, the tenon (which nothing stops there) when
  it reaches the believed goal depth; both only when the part is near the insertion axis (not
  resting on top of the lip or a mortise) and level (:data:`SEAT_PITCH`);
  if the part is not seated after ``t_seat`` (or, the tenon, stuck on the way), a recovery
  (:mod:`teachfit.skills.contact_recovery`), then ``seat`` again: the L's ``retry`` backs out
  along the path, shifts its end across the insertion by the next offset of a ring and
  follows it again (:data:`L_RETRY`); the tenon's ``spiral`` presses its face on the mortise
  and spirals across until the hole catches it (:data:`SPIRAL`);
- ``"open-loop"``: the same path tracked stiffly to its end, as Wang et al. 2019 did.

Task frame ``T`` of both: the captured fixed-part frame turned so that ``T``'s z is ``G``'s x,
i.e. the insertion (towards ``G``'s -x) is ``T``'s -z and "depth" counts along it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TypedDict

import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.core.geometry import Pose, poses_to_array, rotation_to_wxyz
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.demonstrations.dataset import Demonstration
from teachfit.execution.batch import episode_rng
from teachfit.execution.engine import ExecConfig, ExecutionResult, execute
from teachfit.plans.planner import MotionPlanner, PlannerConfig, PlanResult
from teachfit.plans.synth import synth_demo
from teachfit.robot.registry import make_robot
from teachfit.skills.conditions import (
    DepthAbove,
    Done,
    ForceAbove,
    LateralAbove,
    SpeedBelow,
    TiltBelow,
    TimeAbove,
)
from teachfit.skills.contact_recovery import RetryPath, SpiralPush, time_poses
from teachfit.skills.follow import FollowConfig, FollowSetpoints
from teachfit.skills.graph import Node, Skill, Transition
from teachfit.skills.params import ContextParam, SkillParams
from teachfit.skills.primitive import Move
from teachfit.tasks.geometry.parts_cell import G_NOMINAL, PartsCell, PartsCellParams
from teachfit.tasks.registry import build_assembly

#: T in G: z along G's +x (rotation by +90 deg about G's y)
T2G = Pose(np.zeros(3), rotation_to_wxyz(Rotation.from_euler("y", np.pi / 2)))
#: the paper's real-robot results (successes, trials), open loop
PAPER_ROBOT = {"l-groove": (4, 5), "tenon": (3, 5)}
#: path tracking of ``"joined"``: as stiff as the open loop's (softer tracking, 300-1500 N/m
#: and 4-60 N m/rad, let the pivoting L lag and slide onto the lip more often: 5-7 of 10 truly
#: inserted, BENCHMARKS.md), with the seating skill after it
TRACK = FollowConfig(3000.0, 3000.0, 3000.0, (150.0, 150.0, 150.0), 0.0, False, 0.0, 200.0)
STIFF = FollowConfig(3000.0, 3000.0, 3000.0, (150.0, 150.0, 150.0), 0.0, False, 0.5, 200.0)


#: the L's retries (:class:`~teachfit.skills.contact_recovery.RetryPath`): path length backed
#: out (m, to above the opening), offset radius across the insertion (m, beyond its 1.5 mm
#: clearance), speed (m/s), number of retries
L_RETRY = (0.06, 0.002, 0.015, 3)
#: the tenon's spiral push (:class:`~teachfit.skills.contact_recovery.SpiralPush`): pitch (m,
#: under twice its 1 mm clearance), speed (m/s), radius (m, the capture error moved to the
#: first mortise by the rotation error), push (N), advance that ends it (m), time (s); and
#: the resistance along the insertion (N) that stops the tracking as stuck on a mortise face
SPIRAL = (0.0015, 0.01, 0.005, 5.0, 0.003, 20.0)
F_STUCK = 25.0
#: seating push (s) before a recovery
T_SEAT = 2.5

#: the seating push (N) along the insertion: on the FR3 arm 2 N left the tenon's bar at ~3.5 of
#: the seat's 6 mm/s against the joints' friction, and every stalled seat cost a spiral round
#: (4/10 inserted in 60 s at 2 N; 9/10 at 8 N, and the floating tool 10/10 at both)
SEAT_PUSH = 8.0

#: largest pitch (rad) of a seated part
SEAT_PITCH = np.radians(4.0)
#: planning budget per attempt in collision checks: the plan is a function of its inputs and
#: seed alone, not of the machine's load (a budget in seconds made trials irreproducible)
MAX_CHECKS = 2000


def plan_path(part: str, demo: Demonstration | None = None, seed: int = 0) -> PlanResult:
    """Plan ``L2G`` for ``part`` guided by ``demo`` (default: a synthetic one from ``seed``)."""
    asm = build_assembly(part)
    planner = MotionPlanner(asm, PlannerConfig(max_checks=MAX_CHECKS))
    return planner.plan(demo if demo is not None else synth_demo(asm, seed), seed=seed)


def timed_path(
    part: str, plan: PlanResult, speed: float = 0.015, angular_speed: float = 0.25
) -> SetpointTrajectory:
    """The planned poses densified (0.5 mm) and timed at ``speed`` (m/s) and ``angular_speed``
    (rad/s, whichever is slower per step), as set-points of ``L`` in frame ``T``."""
    planner = MotionPlanner(build_assembly(part))
    dense = poses_to_array(planner.dense_poses(plan.poses))
    rel = [T2G.inverse().compose(Pose(s[:3], s[3:])) for s in dense]
    pos = np.array([p.pos for p in rel])
    quat = np.array([p.quat for p in rel])
    t = time_poses(pos, quat, speed, angular_speed)
    return SetpointTrajectory.from_path(t, pos, quat, name=f"{part} plan")


def contact_skill(
    path: SetpointTrajectory, part: str, method: str = "joined", retries: int | None = None
) -> Skill:
    """The path as a skill: tracking, ``seat`` and the cell's recovery (``"joined"``; the L's
    ``retries``, default :data:`L_RETRY`'s; ``0``: no recovery), or stiff tracking only
    (``"open-loop"``); success and error as in the module docstring."""
    goal = build_assembly(part).goal[:3, 3]
    goal_x = float(goal[0])
    recover, extra, rec_nodes, rec_tr = _recovery(path, part, method, retries)
    ctx = {
        "t_path": ContextParam(float(path.duration), "s", "duration of the planned path"),
        "f_seat": ContextParam(4.0, "N", "resistance that marks the part seated"),
        "v_seat": ContextParam(0.006, "m/s", "speed of the seating push"),
        "seat_depth": ContextParam(-(goal_x + 0.004), "m", "along -G x: goal + capture bound"),
        "v_still": ContextParam(0.002, "m/s", "speed below which the part is stuck"),
        "seat_lateral": ContextParam(
            float(np.hypot(goal[1], goal[2])) + 0.012, "m", "off the insertion axis: not inside"
        ),
        "t_max": ContextParam(float(path.duration) + 8.0 + extra, "s", "time limit"),
        "t_seat": ContextParam(T_SEAT, "s", "seating push before a recovery"),
    } | recover
    # near the axis (not on top of the lip or a mortise) and level: the part's z (G's z at the
    # goal) stays at 90 deg from T's z (G's x) within "seat_pitch" (pitch left from the pivot)
    level = TiltBelow(np.pi / 2 + SEAT_PITCH) & ~TiltBelow(np.pi / 2 - SEAT_PITCH)
    inside = TimeAbove("t_path", scope="skill") & ~LateralAbove("seat_lateral") & level
    if part == "tenon":  # nothing stops the bar at its goal: seated = at the believed depth
        ctx["seat_depth"] = ContextParam(-goal_x, "m", "along -G x: the goal")
        seated = inside & DepthAbove("seat_depth")
    else:  # the groove's end wall stops the L
        seated = (
            inside
            & ForceAbove("f_seat", axis="+z")
            & DepthAbove("seat_depth")
            & SpeedBelow("v_still", duration=0.1)
        )
    cfg = TRACK if method == "joined" else STIFF
    follow = Node(
        "path", FollowSetpoints(path, cfg), TimeAbove(path.duration + cfg.settle_time + 1)
    )
    nodes, transitions = [follow], []
    if method == "joined":
        seat = Move(
            (0.0, 0.0, -1.0), "v_seat", push=SEAT_PUSH, stiffness=(1500, 1500, 600, 150, 150, 150)
        )
        doc = "push along the insertion until seated"
        nodes.append(Node("seat", seat, TimeAbove(6.0), doc, keep_orientation=True))
        transitions.append(Transition("path", "seat", Done()))
    nodes += rec_nodes
    transitions += rec_tr
    return Skill(
        f"{part} {method}",
        tuple(nodes),
        tuple(transitions),
        "path",
        SkillParams(ctx, {}),
        seated,
        TimeAbove("t_max", scope="skill") | ForceAbove(150.0, axis="norm"),
        frame="captured fixed-part frame, z along G's x",
    )


def _recovery(
    path: SetpointTrajectory, part: str, method: str, retries: int | None
) -> tuple[dict[str, ContextParam], float, list[Node], list[Transition]]:
    """The recovery of ``"joined"`` on ``part`` (``retries=0``: none): context, the time it
    may add (s), its node and transitions (see the module docstring)."""
    if method != "joined" or retries == 0:
        return {}, 0.0, [], []
    if part == "tenon":
        t_spiral = SPIRAL[-1]
        names = ("pitch", "speed", "radius", "push", "advance")
        units = ("m", "m/s", "m", "N", "m")
        ctx = {
            f"spiral_{n}": ContextParam(v, u, f"spiral push: {n}")
            for n, v, u in zip(names, SPIRAL, units, strict=False)
        }
        stuck = ForceAbove(F_STUCK, axis="+z")
        doc = "press along the insertion, spiral across it until the part advances"
        node = Node("spiral", SpiralPush(), TimeAbove(t_spiral), doc, keep_orientation=True)
        tr = [
            Transition("path", "spiral", stuck),
            Transition("seat", "spiral", TimeAbove("t_seat")),
            Transition("spiral", "seat", Done()),
        ]
        return ctx, 2 * t_spiral, [node], tr
    back, radius, speed, n = L_RETRY
    n = n if retries is None else retries
    ctx = {
        "retry_back": ContextParam(back, "m", "path length backed out by a retry"),
        "retry_radius": ContextParam(radius, "m", "offset across the insertion of a retry"),
        "retry_speed": ContextParam(speed, "m/s", "speed of a retry"),
    }
    t_retry = (3 * back + 0.01) / speed + T_SEAT  # out, across, in again (<= 3 back), seat
    doc = "back out along the path, across by the next offset of a ring, the path's end again"
    node = Node("retry", RetryPath(path, config=TRACK), TimeAbove(2 * t_retry), doc)
    tr = [Transition("seat", "retry", TimeAbove("t_seat")), Transition("retry", "seat", Done())]
    return ctx, n * t_retry, [node], tr


class CaptureError(TypedDict):
    """A capture error as :class:`PartsCellParams` fields: translation (m), rotation (rad)."""

    dx: float
    dy: float
    dz: float
    droll: float
    dpitch: float
    dyaw: float


def capture_error(
    rng: np.random.Generator,
    translation: tuple[float, float] = (0.0005, 0.003),
    rotation: tuple[float, float] = (np.radians(0.5), np.radians(2.0)),
) -> CaptureError:
    """A capture error: translation (m) and rotation (rad) of uniform magnitudes in the given
    ranges, in uniformly random directions; as :class:`PartsCellParams` fields."""
    d = rng.normal(size=3)
    a = rng.normal(size=3)
    t = rng.uniform(*translation) * d / np.linalg.norm(d)
    r = Rotation.from_rotvec(rng.uniform(*rotation) * a / np.linalg.norm(a))
    rpy = r.as_euler("xyz")
    dx, dy, dz, droll, dpitch, dyaw = map(float, (*t, *rpy))
    return CaptureError(dx=dx, dy=dy, dz=dz, droll=droll, dpitch=dpitch, dyaw=dyaw)


def trial_cell(part: str, seed: int, i: int, **error_ranges: tuple[float, float]) -> PartsCell:
    """The cell of trial ``i``: the capture error from ``episode_rng(seed, i)``."""
    err = capture_error(episode_rng(seed, i), **error_ranges)
    return PartsCell(replace(PartsCellParams(part=part), **err))


@dataclass(frozen=True)
class PlanTrial:
    """One in-contact execution: measured success, ground truth, time (s), the capture error
    (translation m, rotation rad), the execution."""

    method: str
    index: int
    success: bool
    ground_truth: bool | None
    time: float
    error_m: float
    error_rad: float
    result: ExecutionResult


def run_plan_trials(
    part: str,
    path: SetpointTrajectory,
    trials: int,
    seed: int = 0,
    method: str = "joined",
    on_trial: Callable[[PlanTrial], None] | None = None,
    robot_name: str = "floating",
    **error_ranges: tuple[float, float],
) -> list[PlanTrial]:
    """``trials`` executions of ``path`` in cells with capture errors from
    :func:`~teachfit.execution.batch.episode_rng` ``(seed, i)`` (same for every method)."""
    skill = contact_skill(path, part, method)
    out = []
    for i in range(trials):
        cell = trial_cell(part, seed, i, **error_ranges)
        err = cell.params
        robot = make_robot(robot_name, cell, seed=i)
        task2world = G_NOMINAL.compose(T2G)
        start = task2world.compose(Pose(path.pos[0], path.quat[0]))
        res = execute(
            skill, robot, start, task2world, task=cell, goal2world=cell.nominal_hole2world,
            config=ExecConfig(max_time=float(skill.params.context["t_max"].value) + 1.0),
        )  # fmt: skip
        robot.close()
        tr = PlanTrial(
            method,
            i,
            res.outcome.value == "success",
            res.ground_truth_inserted,
            res.time_to_success,
            float(np.linalg.norm(err.error.pos)),
            float(err.error.rotation.magnitude()),
            res,
        )
        out.append(tr)
        if on_trial is not None:
            on_trial(tr)
    return out
