"""One search execution as a self-contained, picklable job, and a parallel map over jobs.

Ehlers et al.'s protocols run hundreds of independent executions; each :class:`SearchJob` carries
everything it needs as plain values (task name and overrides, the model as its JSON document,
the start pose, the generator and its seed), so a worker process rebuilds the task, robot and
model from it without pickling any user object. Workers cache the robot per task; a simulated
robot's sensor noise restarts from the job's ``traj_seed`` (its trajectory's seed), so a job reads
the same noise whichever jobs its worker ran before (any ``--workers``, the same table).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.execution.batch import run_batch
from teachfit.execution.search import plan_search, run_search
from teachfit.models.search_model import SearchModel
from teachfit.robot.interface import Robot, restart_noise
from teachfit.robot.registry import make_robot
from teachfit.tasks.base import Task
from teachfit.tasks.registry import get_task
from teachfit.trajectories import SearchTrajectory
from teachfit.trajectories.ergodic import ergodic_metric


@dataclass(frozen=True)
class SearchJob:
    """One execution: ``method`` with ``n_points`` from ``start`` (world ``x y z qw qx qy qz``).

    ``length`` fixes an ergodic trajectory's path length (m); ``traj_seed`` seeds TSHIX and the
    random walk; ``sampling`` is TSHIX's sampler (``"qmc"`` or ``"random"``); ``passes`` its
    number of re-sampled passes; ``robot`` the robot's registry name.
    """

    task: str
    overrides: tuple[tuple[str, float], ...]
    model_json: str
    start: tuple[float, ...]
    method: str
    n_points: int
    traj_seed: int
    feedforward: bool = True
    length: float | None = None
    sampling: str = "qmc"
    robot_seed: int = 0
    passes: int = 1
    robot: str = "floating"


@dataclass(frozen=True)
class JobResult:
    """What one job measured: outcome, planning wall time (s), ergodic metric, and the planned
    path's length in x-y (m) and weighted with rz at the planner's length scale (m)."""

    success: bool
    reason: str
    time_to_insertion: float
    plan_s: float
    path_length: float
    ergodic_metric: float
    weighted_length: float


@cache
def _task(name: str, overrides: tuple[tuple[str, float], ...]) -> Task:
    return get_task(name, **dict(overrides)) if overrides else get_task(name)


@cache
def _robot(name: str, overrides: tuple[tuple[str, float], ...], seed: int, robot: str) -> Robot:
    return make_robot(robot, _task(name, overrides), seed=seed)


@cache
def _model(model_json: str) -> SearchModel:
    return SearchModel.from_dict(json.loads(model_json))


def model_json(model: SearchModel) -> str:
    """The model document a :class:`SearchJob` carries."""
    return json.dumps(model.to_dict(), sort_keys=True)


def run_job(job: SearchJob) -> JobResult:
    """Plan and execute one job (in this process)."""
    task = _task(job.task, job.overrides)
    robot = _robot(job.task, job.overrides, job.robot_seed, job.robot)
    restart_noise(robot, job.traj_seed)  # the job's own, whichever worker ran what before
    model = _model(job.model_json)
    rng = np.random.default_rng(job.traj_seed)
    t0 = time.perf_counter()
    traj = plan_search(
        model,
        job.method,
        job.n_points,
        rng,
        length=job.length,
        sampling=job.sampling,
        passes=job.passes,
    )
    plan_s = time.perf_counter() - t0
    start = Pose(np.array(job.start[:3]), np.array(job.start[3:]))
    run = run_search(robot, task, model, start, traj, feedforward=job.feedforward)
    metric = float(traj.meta.get("ergodic_metric", np.nan))
    if not np.isfinite(metric):
        metric = ergodic_metric(traj.states, model.exploration, t=traj.t)
    o = run.result
    xy, weighted = _lengths(traj)
    return JobResult(
        o.success, f"{o.outcome.value}: {o.reason}", o.time_to_success, plan_s, xy, metric, weighted
    )


def _lengths(traj: SearchTrajectory) -> tuple[float, float]:
    """A planned path's x-y length and its length weighted with rz at the planner's scale (m)."""
    xy = np.linalg.norm(np.diff(traj.states[:, :2], axis=0), axis=1).sum()
    return float(xy), traj.path_length(float(traj.meta.get("length_scale", 1.0)))


def planned_lengths(
    model: SearchModel, method: str, n_points: int, seed: int
) -> tuple[float, float]:
    """The x-y and weighted lengths (m) of the path a job with this model, method, size and
    ``traj_seed`` plans (planning only; the model through its JSON document, as a job gets it)."""
    traj = plan_search(_model(model_json(model)), method, n_points, np.random.default_rng(seed))
    return _lengths(traj)


def pose_tuple(pose: Pose) -> tuple[float, ...]:
    """``(x, y, z, qw, qx, qy, qz)`` of a pose, for :attr:`SearchJob.start`."""
    return tuple(float(v) for v in (*pose.pos, *pose.quat))


def run_jobs(
    jobs: Sequence[SearchJob],
    workers: int | None = None,
    progress: Callable[[], None] | None = None,
) -> list[JobResult]:
    """Run ``jobs`` in order-preserving parallel (``workers=None``: one per core; 0: inline)."""
    return run_batch(run_job, jobs, workers, progress)
