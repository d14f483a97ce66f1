"""What ``teachfit assemble`` runs: a peg-type task's trials built from its options
(:func:`assembly_setup`), a planned part's path and trials in contact (:func:`planned_path`,
:func:`run_plan_trials_keeping`), and the trial its figures show (:func:`shown_trial`).

Trials run one by one or in worker processes; what finished is kept when a fault or an
interrupt ends the rest (:class:`~teachfit.execution.batch.Finished`). The planner and the
trials in contact are imported from :mod:`~teachfit.execution.plan_contact` when called (only
a planned part needs them)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from teachfit.core.errors import TeachfitError
from teachfit.execution.assembly import AssemblyJob, AssemblyTrial, assembly_jobs, method_skill
from teachfit.execution.batch import Finished, keep_each
from teachfit.models.search_model import SearchModel
from teachfit.skills.library import get_skill
from teachfit.skills.params import read_params_toml

if TYPE_CHECKING:
    from teachfit.core.setpoints import SetpointTrajectory
    from teachfit.demonstrations.dataset import Demonstration
    from teachfit.execution.plan_contact import PlanTrial
    from teachfit.plans.planner import PlanResult

#: the parts ``assemble`` plans a path for (from a demonstration) instead of a peg-type skill
PLANNED_PARTS = ("l-groove", "tenon")


def assembly_setup(
    task: tuple[str, str],
    search: Path | None,
    skill: str,
    params: Path | None,
    controller: str,
    hole_error: float,
    trials: int,
    *,
    seed: int,
    yaw_error: float,
    robot: str,
    keep_log: bool,
    robot_options: tuple[tuple[str, Any], ...] = (),
) -> tuple[SearchModel | None, str, list[AssemblyJob]]:
    """The search model, the method (``"joined"`` with a model, else ``"skill"``) and the jobs
    of ``assemble``'s trials (fields of :class:`~teachfit.execution.assembly.AssemblyJob`);
    ``task``: the task as given and its name (what a model learned on it records). Refuses bad
    options before any trial."""
    if trials < 1:
        raise TeachfitError(f"--trials must be >= 1, got {trials}")
    model = SearchModel.load(search, task=task[1]) if search is not None else None
    if model is not None and skill != "peg-in-hole":
        raise TeachfitError(f"the learned search recovers the peg-in-hole skill, not {skill!r}")
    method = "joined" if model is not None else "skill"
    learned: dict[str, float] = {}
    if params is not None:
        sk = method_skill(method, model, skill, controller)
        learned = read_params_toml(params, sk.params, sk.users())
    else:
        get_skill(skill, controller)  # a bad --skill fails before any trial
    jobs = assembly_jobs(
        task[0], [method], [hole_error], trials, model, seed=seed, yaw_error=yaw_error,
        skill=skill, controller=controller, learned=tuple(sorted(learned.items())), robot=robot,
        keep_log=keep_log, robot_options=robot_options,
    )  # fmt: skip
    return model, method, jobs


def shown_trial(trials: Sequence[AssemblyTrial]) -> AssemblyTrial:
    """The trial ``--plot`` and ``--render`` show: the first whose search succeeded, else the
    first."""
    return next((t for t in trials if "search" in t.nodes and t.success), trials[0])


def capture_ranges(err: float, ang: float) -> dict[str, tuple[float, float]]:
    """The capture error ranges of a planned part's trials: translation from 0.5 mm (or less)
    to ``err`` (m), rotation from 0.5 deg (or less) to ``ang`` (rad)."""
    lo_t, lo_r = min(0.0005, err), min(np.radians(0.5), ang)
    return {"translation": (lo_t, err), "rotation": (lo_r, ang)}


def planned_path(
    part: str, demo: Demonstration | None, seed: int
) -> tuple[PlanResult, SetpointTrajectory]:
    """The plan for ``part`` (guided by ``demo``; ``None``: a synthetic one from ``seed``) and
    its timed path; no plan is an error."""
    from teachfit.execution.plan_contact import plan_path, timed_path

    plan = plan_path(part, demo, seed)
    if not plan.success:
        raise TeachfitError(f"no plan for {part}: {plan.message}")
    return plan, timed_path(part, plan)


def run_plan_trials_keeping(
    part: str,
    path: SetpointTrajectory,
    trials: int,
    seed: int,
    progress: Callable[[], None],
    translation: tuple[float, float],
    rotation: tuple[float, float],
) -> Finished[PlanTrial]:
    """:func:`~teachfit.execution.plan_contact.run_plan_trials` (the joined method) keeping
    the trials that finished when a fault or an interrupt ends the rest; ``progress`` is called
    after each trial; ``translation`` (m) and ``rotation`` (rad): the capture error ranges
    (:func:`capture_ranges`)."""
    from teachfit.execution.plan_contact import run_plan_trials

    return keep_each(
        trials,
        lambda done: run_plan_trials(
            part, path, trials, seed, on_trial=done, translation=translation, rotation=rotation
        ),
        progress,
    )
