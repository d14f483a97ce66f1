"""Set-ups drawn from a task's error distribution: learning over several, testing on held-out ones.

A set-up (:class:`~teachfit.execution.skill_trial.SkillSetup`) fixes what a person teaching the
robot would fix once: the taught hole pose, off the true one by the task's taught-pose error
(``hole_pos_sigma`` per axis, ``hole_yaw_sigma``), and the start poses above it. Parameters
learned on one set-up can fit its particular error (a hole taught 0.3 mm to the left) and fail
on the next; learning over ``K`` set-ups makes the trial cost the mean over all of them,

    cost = 1 / (K n) sum_k sum_i q_ki        (k: set-up, i: start),

so what is learned must hold across the error distribution rather than on one draw of it.

Two disjoint streams of set-ups, both reproducible from the experiment's ``seed``:

* the **training** stream, set-up ``k`` drawn from the seed sequence ``(seed, 0, k)``; with one
  set-up it is the experiment's own set-up, drawn from ``seed`` alone (what a run without
  ``--setups`` always used, so stored studies and figures keep their meaning);
* the **held-out** stream, set-up ``k`` drawn from ``(seed, 1, k)``: never a training set-up,
  whatever the number of either (``skill run --setups N``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from teachfit.core.errors import SkillError
from teachfit.core.geometry import Pose
from teachfit.execution.skill_trial import SkillSetup, peg_in_hole_setup
from teachfit.skills.graph import Skill
from teachfit.tasks.base import Task

#: stream tags of the seed sequence ``(seed, stream, k)``
TRAINING, HELD_OUT = 0, 1


@dataclass(frozen=True)
class DrawnSetups:
    """``setups`` set-ups of one stream joined into one :class:`SkillSetup`, which set-up each
    of its starts belongs to (``of_start[i]`` in ``range(setups)``) and each set-up's taught
    hole (``taught2world[k]``, world frame)."""

    setup: SkillSetup
    of_start: tuple[int, ...]
    taught2world: tuple[Pose, ...]

    @property
    def setups(self) -> int:
        return len(self.taught2world)

    def taught_errors(self) -> list[Pose]:
        """Per set-up, the true hole in its taught hole's frame (m, rad): how far it is off."""
        hole = self.setup.task.hole2world
        return [t.inverse().compose(hole) for t in self.taught2world]

    def per_setup(self, successes: Sequence[bool]) -> list[bool]:
        """Per set-up whose executions all finished: whether every one succeeded
        (``successes`` in the order of the starts, those that finished)."""
        n = len(self.of_start) // self.setups
        done = len(successes) // n
        return [all(successes[k * n : (k + 1) * n]) for k in range(done)]


def draw_setups(
    task: Task,
    seed: int,
    n_starts: int = 4,
    controller: str = "adaptive",
    skill: Skill | None = None,
    setups: int = 1,
    held_out: bool = False,
) -> DrawnSetups:
    """``setups`` set-ups of ``task`` from the training (or ``held_out``) stream of ``seed``,
    ``n_starts`` starts each, joined: the starts in set-up order, each start in the task frame
    of its own set-up's taught hole (:meth:`SkillSetup.frame`)."""
    if setups < 1:
        raise SkillError(f"--setups must be >= 1, got {setups}")
    if setups == 1 and not held_out:
        one = peg_in_hole_setup(task, seed, n_starts, controller, skill)
        return DrawnSetups(one, (0,) * len(one.starts), (one.task2world,))
    stream = HELD_OUT if held_out else TRAINING
    drawn = [
        peg_in_hole_setup(task, (seed, stream, k), n_starts, controller, skill)
        for k in range(setups)
    ]
    first = drawn[0]
    starts = tuple(st for d in drawn for st in d.starts)
    frames = tuple(d.frame(i) for d in drawn for i in range(len(d.starts)))
    of_start = tuple(k for k, d in enumerate(drawn) for _ in d.starts)
    joined = SkillSetup(first.skill, task, first.task2world, first.goal2world, starts, frames)
    return DrawnSetups(joined, of_start, tuple(d.task2world for d in drawn))
