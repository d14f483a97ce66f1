"""``skill run``'s executions: a skill from each start of its set-up, in this process, what
finished kept when a fault or an interrupt ends the rest (:class:`~teachfit.execution.batch.
Finished`), and the episodes its recordings store."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from teachfit.core.geometry import Pose
from teachfit.execution.batch import Finished, run_batch_keeping
from teachfit.execution.engine import ExecutionResult
from teachfit.execution.episode import Episode
from teachfit.execution.skill_trial import SkillSetup, SkillTrial


def hole_estimate_error(setup: SkillSetup) -> Pose:
    """The true hole in the estimated hole's frame (m, rad): how far the estimate is off."""
    return setup.task2world.inverse().compose(setup.task.hole2world)


def run_starts(
    trial: SkillTrial, learned: Mapping[str, float] | None, starts: int
) -> Finished[ExecutionResult]:
    """One execution from each of the first ``starts`` starts of ``trial``'s set-up, each in
    its own task frame; ``learned``: the learned values (``None``: the defaults)."""
    setup = trial.setup
    return run_batch_keeping(
        lambda i: trial.run(learned, setup.starts[i], setup.frame(i)), range(starts), 0
    )


def start_episodes(setup: SkillSetup, traces: Sequence[ExecutionResult]) -> list[Episode]:
    """The episodes of the executions that finished, in the order of ``setup``'s starts."""
    return [
        Episode.of_skill(tr, setup.skill, st) for tr, st in zip(traces, setup.starts, strict=False)
    ]
