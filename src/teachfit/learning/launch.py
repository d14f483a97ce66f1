"""Opening a skill-learning run: every check and every policy before the first trial.

- a request that cannot run is refused before anything is written: an unknown storage scheme
  or a missing driver, a bad Ray address or ``--workers 0`` with Ray, an unknown method or task;
- a real robot runs its trials one at a time in the calling process (one arm; no Ray);
- a new study gets the learners' default options (:func:`method_options`); a stored study of
  the same method resumes with its stored options, and a stored Latin hypercube cannot grow;
- a database that holds another study is named as such.

:func:`run_learning` then runs the trials on worker processes or on Ray.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from teachfit.core.params import LearningError
from teachfit.learning.objective import SkillObjective
from teachfit.learning.runner import RunReport, run_study
from teachfit.learning.storage import check_storage
from teachfit.learning.study import METHODS, Study, StudyMismatchError, TrialRecord, stored_tags


def method_options(method: str, trials: int) -> dict[str, object]:
    """Learner options of a new study: LHS designs ``trials`` points, BO starts with
    ``min(10, trials // 4)`` random trials (at least 2); CMA-ES and PSO keep their defaults."""
    if method == "lhs":
        return {"n": int(trials)}
    if method == "bo":
        return {"n_startup": max(2, min(10, trials // 4))}
    return {}


@dataclass(frozen=True)
class LearnRequest:
    """What ``learn skill`` asks for (see its options): the task and skill, the learner and
    its budget, where the study is stored, where the trials run (``workers``: None = all
    cores, 0 = this process; ``ray``: ``"local"`` or a cluster's address), on which robot, and
    over how many set-ups each trial is evaluated (``setups``)."""

    task: str
    skill: str
    method: str
    trials: int
    study: str
    resume: bool = False
    workers: int | None = None
    ray: str | None = None
    controller: str = "adaptive"
    seed: int = 0
    starts: int = 4
    overrides: tuple[tuple[str, float], ...] = ()
    robot: str = "floating"
    host: str = ""
    realtime: bool = True
    setups: int = 1
    confirm: bool = False
    reflex_force: float | None = None


@dataclass(frozen=True)
class Launch:
    """An opened learning run: its study, objective, learner options, the workers the trials
    run on, and notes for the user (e.g. that a real robot runs one trial at a time)."""

    request: LearnRequest
    study: Study
    objective: SkillObjective
    options: dict[str, Any]
    workers: int | None
    notes: tuple[str, ...] = ()


def open_learning(req: LearnRequest) -> Launch:
    """Check ``req``, apply the policies above and open (or resume) its study."""
    check_storage(req.study)  # an unknown scheme or a missing driver: before any work
    check_ray_workers(req.ray, req.workers)
    if req.trials < 1:
        raise LearningError(f"--trials must be >= 1, got {req.trials}")
    if req.method not in METHODS:
        raise LearningError(f"unknown learning method {req.method!r}; known: {list(METHODS)}")
    from teachfit.robot.registry import ROBOTS
    from teachfit.tasks.registry import get_task

    get_task(req.task)  # an unknown task fails here, before any study file is created
    if req.confirm and not req.host:
        raise LearningError("--confirm asks before a real robot's resets: give --host with it")
    workers = req.workers
    notes: tuple[str, ...] = ()
    if req.robot in ROBOTS and not ROBOTS[req.robot].simulated:
        if req.ray:
            raise LearningError(f"--ray runs trials in parallel: not on the one real {req.robot}")
        if workers != 0:
            notes = (f"trials on the real {req.robot} run one at a time, in this process",)
        workers = 0  # one arm: trials cannot run in parallel worker processes
    obj = SkillObjective(
        req.task, req.skill, req.controller, req.seed, req.starts, req.overrides, req.robot,
        req.host, req.realtime, req.setups, req.confirm, req.reflex_force,
    )  # fmt: skip
    options = _options(req)
    try:
        study = Study(
            req.study, task=req.task, skill=obj.trial().setup.skill.name, space=obj.space,
            method=req.method, seed=req.seed, options=options, penalty=obj.penalty,
            resume=req.resume, context=obj.context(),
        )  # fmt: skip
    except StudyMismatchError as exc:
        raise StudyMismatchError(
            f"{exc} -- this database holds another study; choose "
            "another --study or the same settings"
        ) from exc
    return Launch(req, study, obj, options, workers, notes)


def _options(req: LearnRequest) -> dict[str, Any]:
    """The learner's options: a stored study of the same method keeps its own (e.g. the LHS
    design's size, which cannot grow); a new one gets :func:`method_options`."""
    tags = stored_tags(req.study)
    same = tags is not None and tags.get("method") == req.method
    stored = tags.get("options", {}) if tags is not None and same else {}
    options = dict(stored) if same else method_options(req.method, req.trials)
    n_design = options.get("n", req.trials)
    if same and req.method == "lhs" and isinstance(n_design, int) and n_design < req.trials:
        raise LearningError(
            f"the stored Latin hypercube has {options.get('n')} points; --trials {req.trials} "
            "cannot extend it (a new design needs a new --study)"
        )
    return options


def check_ray_workers(ray: str | None, workers: int | None) -> None:
    """Refuse a malformed ``--ray`` address, a missing Ray or ``--workers 0`` with it."""
    if ray is None:
        return
    from teachfit.learning.ray_runner import check_ray

    check_ray(ray)
    if workers == 0:
        raise LearningError(
            "--workers 0 runs trials in this process, not on Ray: give --workers 1 or more "
            "with --ray, or leave --workers out"
        )


def run_learning(
    launch: Launch, on_trial: Callable[[TrialRecord], None] | None = None
) -> RunReport:
    """Run the study's trials up to the request's budget, on Ray or on worker processes."""
    req = launch.request
    if req.ray:
        from teachfit.learning.ray_runner import run_study_ray

        return run_study_ray(
            launch.study, launch.objective, req.trials, address=req.ray,
            workers=launch.workers, on_trial=on_trial,
        )  # fmt: skip
    return run_study(
        launch.study, launch.objective, req.trials, workers=launch.workers, on_trial=on_trial
    )
