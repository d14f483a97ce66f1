"""Execution: the one engine every skill, search, replay and teacher runs through.

A skill's view::

    from teachfit.execution import SkillTrial, peg_in_hole_setup
    setup = peg_in_hole_setup(task, seed=0, n_starts=4, controller="adaptive")
    trial = SkillTrial(setup, controller="adaptive", robot="floating")
    space = setup.skill.space                 # ParamSpace of the learned parameters
    outcome = trial(space.from_unit(u))       # 4 executions -> successes, costs, mean cost

A run's recording (``--log``)::

    from teachfit.execution import RunInfo, read_run_log, write_run_log
    write_run_log("run.h5", results, RunInfo.here("assemble", task, "floating", seed, "rrt"))
    run = read_run_log("run.h5")              # run.info, run.episodes[i].result (ExecutionResult)
"""

from teachfit.execution.batch import episode_rng, episode_seed, run_batch
from teachfit.execution.engine import ExecConfig, ExecutionResult, NodeVisit, execute
from teachfit.execution.follow import run_trajectory
from teachfit.execution.log import ExecutionLog
from teachfit.execution.metric import LearningMetric
from teachfit.execution.skill_trial import SkillSetup, SkillTrial, TrialOutcome, peg_in_hole_setup

__all__ = [
    "Episode",
    "ExecConfig",
    "ExecutionLog",
    "ExecutionResult",
    "LearningMetric",
    "NodeVisit",
    "RunInfo",
    "RunLog",
    "SkillSetup",
    "SkillTrial",
    "TrialOutcome",
    "episode_rng",
    "episode_seed",
    "execute",
    "peg_in_hole_setup",
    "read_run_log",
    "run_batch",
    "run_trajectory",
    "write_run_log",
]

#: run logs (:mod:`teachfit.execution.recording`, HDF5): imported when first asked for
_RECORDING = ("Episode", "RunInfo", "RunLog", "read_run_log", "write_run_log")


def __getattr__(name: str) -> object:
    if name in _RECORDING:
        from teachfit.execution import recording

        return getattr(recording, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
