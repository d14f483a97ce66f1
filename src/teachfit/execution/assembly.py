"""The whole peg-type assembly over trials: taught hole -> approach -> skill -> search recovery.

Each trial draws, from :func:`~teachfit.execution.batch.episode_seed` ``(seed, i)`` only (so
every method sees the same trials), a *taught* hole pose: the true hole moved by exactly
``hole_error`` (m) in a uniformly random direction of the surface plane, its yaw by a uniform
``+-yaw_error`` (rad, tasks whose yaw matters), a start 25 mm above it (1 mm jitter) and, on a
simulated robot, its sensor noise (:class:`~teachfit.robot.interface.NoiseSeeded`: the same
trial reads the same noise under every method, in any process, after any other trial). The
skill's task frame is the taught hole; the true hole is known only to the simulator (ground
truth, recorded beside the measured outcome). A searching method is told the error's size,
not its direction: the search's spread is at least ``hole_error`` wide (``search_radius``).
Methods (:data:`METHODS`):

- ``"skill"``: Johannsmeier et al.'s skill alone (its recovery only retracts);
- ``"search"``: Ehlers et al.'s learned search alone, started on the surface at the taught pose:
  the part is put down there (the joined skill's ``contact`` node) and then searched with the
  same :class:`~teachfit.skills.search.LearnedSearch` node as the joined skill's until the
  task's success detector fires;
- ``"open-loop"``: the plan executed open loop: move above the taught hole, then straight down
  to the insertion depth, stiff, whatever the contact says;
- ``"joined"``: the skill whose recovery is the learned search
  (:mod:`teachfit.skills.peg_in_hole_search`);
- ``"joined-learned"`` (:data:`JOINED_LEARNED`): the same graph, meant to run with learned
  parameters (``bench assembly --params``) beside the defaults' ``"joined"``.

Jobs carry plain values (the model as its JSON document) so they run in worker processes.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import cache, partial
from typing import Any

import numpy as np

from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import Pose
from teachfit.execution.batch import episode_rng, episode_seed, run_batch
from teachfit.execution.engine import ExecConfig, ExecutionResult, execute
from teachfit.execution.search import task_follow_config
from teachfit.models.search_model import SearchModel
from teachfit.robot.interface import Robot, restart_noise
from teachfit.robot.registry import make_robot
from teachfit.skills import peg_in_hole, peg_in_hole_search
from teachfit.skills.conditions import DepthAbove, Detected, Done, TimeAbove
from teachfit.skills.controllers import controller_spec
from teachfit.skills.graph import Node, Skill, Transition
from teachfit.skills.library import get_skill
from teachfit.skills.params import SkillParams
from teachfit.skills.primitive import MoveTo
from teachfit.skills.search import LearnedSearch
from teachfit.tasks.base import Task
from teachfit.tasks.registry import get_task

METHODS = ("skill", "search", "open-loop", "joined")
#: the joined skill run with learned parameters (not in :data:`METHODS`: it needs them)
JOINED_LEARNED = "joined-learned"
#: start height above the taught hole's surface (m)
START_HEIGHT = 0.025


def taught_hole(task: Task, hole_error: float, yaw_error: float, rng: np.random.Generator) -> Pose:
    """The true hole moved ``hole_error`` (m) in a random direction, yaw within ``+-yaw_error``
    (rad, only where the yaw matters)."""
    if not (np.isfinite(hole_error) and hole_error >= 0 and yaw_error >= 0):
        raise TeachfitError(f"hole error must be >= 0, got {hole_error} m, {yaw_error} rad")
    ang = rng.uniform(0.0, 2 * np.pi)
    yaw = rng.uniform(-yaw_error, yaw_error) if task.has_rz else 0.0
    err = Pose.from_xyz_rz(hole_error * np.cos(ang), hole_error * np.sin(ang), 0.0, yaw)
    return task.hole2world.compose(err)


def open_loop_skill(controller: str = "adaptive") -> Skill:
    """The plan executed open loop: above the taught hole, then straight down to depth."""
    base = peg_in_hole.build(controller)
    stiff = (2000.0, 2000.0, 2000.0, 80.0, 80.0, 80.0)
    # the motion limits by the names of the learned parameters
    fast = partial(
        MoveTo,
        stiffness=stiff,
        a_max="a_max",
        w_max="w_max",
        dw_max="dw_max",
        speed_factor="speed_factor",
    )
    nodes = (
        Node(
            "approach",
            fast(goal=(0.0, 0.0, "approach_height"), yaw=0.0, tilt=0.0, v_max="v_max"),
            TimeAbove("t_approach"),
        ),
        Node(
            "descend",
            fast(goal=(0.0, 0.0, "-depth"), v_max="v_insert"),
            TimeAbove("t_approach"),
        ),
    )
    return Skill(
        "open-loop",
        nodes,
        (Transition("approach", "descend", Done()),),
        "approach",
        base.params,
        DepthAbove("depth"),
        base.error,
        doc="the taught hole's plan executed open loop",
    )


def search_skill(
    model: SearchModel, controller: str = "adaptive", task: Task | None = None
) -> Skill:
    """Ehlers et al. 2019 alone: the joined skill's search node from the start pose until the task's
    success detector fires (as Ehlers et al.'s runner,
    :func:`~teachfit.skills.follow.follow_skill`), with the task's follower settings where
    ``task`` is given (:func:`~teachfit.execution.search.task_follow_config`: the hold once the
    part sank into the hole -- dragged on, a dropped part wedges on the arm)."""
    joined = peg_in_hole_search.build(model, controller)
    node = joined.node("search")
    prim = node.primitive
    if task is not None and isinstance(prim, LearnedSearch):
        follow = replace(task_follow_config(task), tilt=None, settle_time=0.0)
        prim = replace(prim, follow=follow)
    # put the part down where it was taught first, as a person does before searching: a search
    # that starts moving while the part still falls turns it on the way down (on the arm the
    # socket's plug then lands in its recess turned and jams there)
    # (the joined skill's own node and its own sign of contact)
    touched = next(t.condition for t in joined.transitions if t.source == "contact")
    return Skill(
        "search",
        (joined.node("contact"), Node("search", prim, TimeAbove("t_search") | Done())),
        (Transition("contact", "search", touched),),
        "contact",
        SkillParams(dict(joined.params.context), dict(joined.params.learned)),
        Detected(),
        joined.error,
        doc="learned search alone from the taught pose",
    )


def method_skill(
    method: str, model: SearchModel | None, skill: str, controller: str, task: Task | None = None
) -> Skill:
    """The skill graph a method runs (``skill``: the base skill spec for ``"skill"``; ``task``:
    the search's follower settings, see :func:`search_skill`)."""
    if method == "skill":
        return get_skill(skill, controller)
    if method == "open-loop":
        return open_loop_skill(controller)
    if model is None:
        raise TeachfitError(f"method {method!r} needs a search model (--search MODEL)")
    if method == "search":
        return search_skill(model, controller, task)
    if method in ("joined", JOINED_LEARNED):
        return peg_in_hole_search.build(model, controller)
    known = (*METHODS, JOINED_LEARNED)
    raise TeachfitError(f"unknown assembly method {method!r}; choose from {known}")


@dataclass(frozen=True)
class AssemblyJob:
    """One trial of one method (plain values; see the module docstring)."""

    task: str
    overrides: tuple[tuple[str, float], ...]
    model_json: str
    method: str
    hole_error: float
    index: int
    seed: int = 0
    yaw_error: float = 0.0
    skill: str = "peg-in-hole"
    controller: str = "adaptive"
    learned: tuple[tuple[str, float], ...] = ()
    robot: str = "floating"
    keep_log: bool = False
    #: a real robot's options, e.g. ``(("host", "127.0.0.1"), ("realtime", False))``
    robot_options: tuple[tuple[str, Any], ...] = ()


@dataclass(frozen=True)
class AssemblyTrial:
    """What one trial did: measured success, time to insertion (s, NaN on failure), simulator
    ground truth, the taught hole's offset (m, world x-y), nodes visited; ``result`` the full
    execution (with its log) when the job asked to keep it."""

    method: str
    hole_error: float
    index: int
    success: bool
    time: float
    ground_truth: bool | None
    offset: tuple[float, float]
    nodes: tuple[str, ...]
    reason: str
    result: ExecutionResult | None = None


@cache
def _task(name: str, overrides: tuple[tuple[str, float], ...]) -> Task:
    return get_task(name, **dict(overrides))


#: the robots this process built for its trials, by task, overrides, robot and its options
_ROBOTS: dict[tuple[Any, ...], Robot] = {}


def _robot(
    name: str,
    overrides: tuple[tuple[str, float], ...],
    robot: str,
    options: tuple[tuple[str, Any], ...] = (),
) -> Robot:
    key = (name, overrides, robot, options)
    if key not in _ROBOTS:
        _ROBOTS[key] = make_robot(robot, _task(name, overrides), seed=0, **dict(options))
    return _ROBOTS[key]


def close_robots() -> None:
    """Close the robots this process built for its trials (a real arm's connection) and
    forget them."""
    while _ROBOTS:
        _ROBOTS.popitem()[1].close()


@cache
def _model(doc: str) -> SearchModel | None:
    return SearchModel.from_dict(json.loads(doc)) if doc else None


def _search_context(job: AssemblyJob, skill: Skill) -> dict[str, float]:
    """The search's context of a trial where ``skill`` searches: its seed (the trial's) and
    its least spread, the taught hole's error (``search_radius``: a human's search narrower
    than the error is widened to it; see :func:`~teachfit.skills.search.recentred`)."""
    out = {}
    if "search_seed" in skill.params.context:
        out["search_seed"] = float(episode_seed(job.seed, job.index))
    if "search_radius" in skill.params.context:
        out["search_radius"] = job.hole_error
    return out


def run_assembly_job(job: AssemblyJob) -> AssemblyTrial:
    """Run one trial in this process (task, robot and model cached per process)."""
    task = _task(job.task, job.overrides)
    robot = _robot(job.task, job.overrides, job.robot, job.robot_options)
    restart_noise(robot, episode_seed(job.seed, job.index))  # whatever ran before it here
    rng = episode_rng(job.seed, job.index)
    taught = taught_hole(task, job.hole_error, job.yaw_error, rng)
    base = method_skill(job.method, _model(job.model_json), job.skill, job.controller, task)
    ctx = peg_in_hole.hole_context(task, rng, base.params.context)
    values = dict(ctx.values)
    if job.method == "search":  # start on the surface at the taught pose
        start = taught.compose(Pose(np.array([0.0, 0.0, task.surface_z - task.hole2world.pos[2]])))
    else:
        jitter = rng.normal(0.0, 0.001, 2)
        above = task.surface_z - task.hole2world.pos[2] + START_HEIGHT
        start = taught.compose(Pose.from_xyz_rz(jitter[0], jitter[1], above, 0.0))
    values |= _search_context(job, base)
    sk = base.with_context({k: v for k, v in values.items() if k in base.params.context})
    learned = {k: v for k, v in job.learned if k in sk.params.learned}
    t_max = sk.params.context["t_max"].value
    res = execute(
        sk,
        robot,
        start,
        taught,
        learned,
        task=task,
        goal2world=ctx.goal2world,
        config=ExecConfig(max_time=t_max + 1.0, log_rate=100.0 if job.keep_log else 20.0),
        controller=controller_spec(job.controller, sk.resolve(learned)),
    )
    off = taught.pos[:2] - task.hole2world.pos[:2]
    return AssemblyTrial(
        job.method,
        job.hole_error,
        job.index,
        res.success,
        res.time_to_success,
        res.ground_truth_inserted,
        (float(off[0]), float(off[1])),
        tuple(v.node for v in res.visits),
        f"{res.outcome.value}: {res.reason}",
        res if job.keep_log else None,
    )


def assembly_jobs(
    task: str,
    methods: Sequence[str],
    hole_errors: Sequence[float],
    trials: int,
    model: SearchModel | None = None,
    *,
    overrides: Sequence[tuple[str, float]] | None = None,
    seed: int = 0,
    yaw_error: float = 0.0,
    skill: str = "peg-in-hole",
    controller: str = "adaptive",
    learned: tuple[tuple[str, float], ...] = (),
    robot: str = "floating",
    keep_log: bool = False,
    robot_options: tuple[tuple[str, Any], ...] = (),
) -> list[AssemblyJob]:
    """Jobs for every method x hole error x trial (trial ``i`` is the same for all methods);
    the keyword arguments are the :class:`AssemblyJob` fields of the same names."""
    if trials < 1:
        raise TeachfitError(f"number of trials must be >= 1, got {trials}")
    for m in methods:
        method_skill(m, model, skill, "impedance")  # fail early
    doc = "" if model is None else json.dumps(model.to_dict(), sort_keys=True)
    ov = tuple(sorted(overrides or ()))
    return [
        AssemblyJob(
            task,
            ov,
            doc,
            m,
            float(e),
            i,
            seed=seed,
            yaw_error=yaw_error,
            skill=skill,
            controller=controller,
            learned=learned,
            robot=robot,
            keep_log=keep_log,
            robot_options=robot_options,
        )  # fmt: skip
        for m in methods
        for e in hole_errors
        for i in range(trials)
    ]


def run_assembly(
    jobs: Sequence[AssemblyJob],
    workers: int | None = 0,
    progress: Callable[[], None] | None = None,
) -> list[AssemblyTrial]:
    """Run ``jobs`` in order (``workers``: processes; 0: in this process)."""
    return run_batch(run_assembly_job, jobs, workers, progress)
