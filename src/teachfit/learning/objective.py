"""The skill-learning objective: one trial = one learned parameter set, several executions.

:class:`SkillObjective` is a small frozen (hence picklable and hashable) description of an
experiment -- task name and parameter overrides, skill, controller, set-up seed, number of
start poses -- that turns into ``params -> TrialResult`` in whichever process calls it (a
worker of :func:`~teachfit.learning.runner.run_study`, a Ray worker, or this one). The MuJoCo
scene and robot are built once per process and objective and then reused across trials.

Cost (Johannsmeier et al. 2019, Sec. V): the mean over the starts of the learning metric
(:class:`~teachfit.execution.metric.LearningMetric`): the time from first contact to full
insertion (s) on success, ``t_max + k_d * remaining distance`` on failure. A trial is
feasible if any start succeeded. ``info`` carries ``success_rate``, ``sim_s`` (simulated robot
seconds of all executions; on a simulated robot the recovery retract after a failure is
skipped, as every execution starts from a reset) and ``wall_s``; on a real arm also
``reflex_retries`` (executions run again after a safety reflex), ``reset_peak_lateral_n``
(the largest lateral force, N, while a reset left the hole,
:mod:`teachfit.robot.franka.reset_path`) and ``reset_handover_lateral_n`` (the largest the
skill left at the hand-over to a reset: the reading at the take-over, the next, and those
still falling from it in the reset's first 50 ms,
:class:`~teachfit.robot.franka.reset_path.ResetGuard`), ``loop_p99_us`` and ``loop_over_1ms``
(the 1 kHz loop's 99th percentile compute time, µs, and its ticks over 1 ms, over the trial's
last 120 s at most).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from teachfit.core.params import LearningError, ParamSpace
from teachfit.learning.base import TrialResult

#: distance (m) at which a crashed or diverged trial is penalised: well beyond any region of
#: interest, so every such trial costs more than every ordinary failure
PENALTY_DISTANCE = 0.05

_CACHE: dict[SkillObjective, Any] = {}  # objective -> SkillTrial, per process


@dataclass(frozen=True)
class SkillObjective:
    """A picklable learning objective for a skill on a task.

    Parameters
    ----------
    task : str
        Built-in task name (:func:`teachfit.tasks.registry.get_task`).
    skill : str
        Built-in skill name or skill ``.toml``.
    controller : str
        ``"adaptive"`` (learns the controller's meta-parameters too) or ``"impedance"``.
    seed : int
        Seed of the experiment's fixed part: hole estimate, start poses, sensor noise.
    n_starts : int
        Executions per trial and set-up (four in the paper).
    task_overrides : tuple of (name, value)
        Task parameter overrides, e.g. ``(("hole_pos_sigma", 0.001),)`` (SI units).
    robot : str
        Robot name in :data:`teachfit.robot.registry.ROBOTS`; ``host`` a real robot's address.
    setups : int
        Set-ups each trial is evaluated on (:mod:`teachfit.execution.setups`, training stream):
        the cost is the mean over ``setups x n_starts`` executions.
    confirm : bool
        On a real robot, ask on the terminal before each reset (not part of the study).
    reflex_force : float or None
        On a real robot, the collision reflex's force threshold (N; ``None``: the driver's
        default; not part of the study).
    """

    task: str
    skill: str = "peg-in-hole"
    controller: str = "adaptive"
    seed: int = 0
    n_starts: int = 4
    task_overrides: tuple[tuple[str, float], ...] = ()
    robot: str = "floating"
    host: str = ""
    realtime: bool = True
    setups: int = 1
    confirm: bool = False
    reflex_force: float | None = None

    def __post_init__(self) -> None:
        if self.n_starts < 1:
            raise LearningError(f"n_starts must be >= 1, got {self.n_starts}")
        if self.setups < 1:
            raise LearningError(f"--setups must be >= 1, got {self.setups}")
        object.__setattr__(self, "task_overrides", tuple(sorted(self.task_overrides)))

    # ---------------------------------------------------------------------------- set-up
    def trial(self) -> Any:
        """The :class:`~teachfit.execution.skill_trial.SkillTrial` (built once per process)."""
        found = _CACHE.get(self)
        if found is None:
            from teachfit.execution.setups import draw_setups
            from teachfit.execution.skill_trial import SkillTrial
            from teachfit.skills.library import get_skill
            from teachfit.tasks.registry import get_task

            task = get_task(self.task, **dict(self.task_overrides))
            skill = get_skill(self.skill, self.controller)
            drawn = draw_setups(task, self.seed, self.n_starts, self.controller, skill, self.setups)
            from teachfit.execution.engine import ExecConfig

            # the real robot's own options (checked by its factory)
            options: dict[str, Any] = (
                {"host": self.host, "realtime": self.realtime} if self.host else {}
            )
            if self.host and self.confirm:
                options["confirm"] = True  # a person confirms each reset
            if self.host and self.reflex_force is not None:
                options["reflex_force"] = self.reflex_force
            # a simulated robot is reset before every execution: the recovery retract after a
            # failure would only cost compute (its robot time is not in the cost), a real one
            # needs it
            config = None if self.host else ExecConfig(recovery_time=0.0)
            found = SkillTrial(
                drawn.setup,
                self.controller,
                robot=self.robot,
                seed=self.seed,
                config=config,
                **options,
            )
            _CACHE.clear()  # one experiment per worker at a time: keep memory flat
            _CACHE[self] = found
        return found

    @property
    def space(self) -> ParamSpace:
        """The skill's learned parameters and their domains."""
        return self.trial().setup.skill.space

    @property
    def penalty(self) -> float:
        """Cost of a crashed or diverged trial (s): a failure ``PENALTY_DISTANCE`` away."""
        return float(self.trial().metric.failure_cost(PENALTY_DISTANCE))

    def context(self) -> dict[str, Any]:
        """JSON-able description stored with a study and compared on resume (``setups`` only
        when above one, so that a study stored before the option resumes)."""
        ctx: dict[str, Any] = {
            "controller": self.controller,
            "robot": self.robot,
            "setup_seed": int(self.seed),
            "n_starts": int(self.n_starts),
            "task_overrides": {k: float(v) for k, v in self.task_overrides},
        }
        if self.setups > 1:
            ctx["setups"] = int(self.setups)
        return ctx

    # ---------------------------------------------------------------------------- trials
    def outcome(self, params: Mapping[str, float] | None) -> Any:
        """The full :class:`~teachfit.execution.skill_trial.TrialOutcome` (traces with logs)."""
        return self.trial()(params)

    def held_out(self, params: Mapping[str, float] | None, setups: int) -> tuple[bool, ...]:
        """Success of each execution of ``params`` on ``setups`` held-out set-ups (``n_starts``
        starts each, :mod:`teachfit.execution.setups`): set-ups no trial was evaluated on."""
        return tuple(ok for ok, _ in self.held_out_runs(params, setups))

    def held_out_runs(
        self,
        params: Mapping[str, float] | None,
        setups: int,
        progress: Callable[[], None] | None = None,
    ) -> list[tuple[bool, str]]:
        """:meth:`held_out`'s executions in order: success and the outcome with its reason
        (``"outcome: reason"``); ``progress()`` after each."""
        from teachfit.execution.setups import draw_setups
        from teachfit.skills.library import get_skill

        tr = self.trial()
        skill = get_skill(self.skill, self.controller)
        drawn = draw_setups(
            tr.setup.task, self.seed, self.n_starts, self.controller, skill, setups, True
        )
        s = drawn.setup
        out = []
        for i, st in enumerate(s.starts):
            r = tr.run(params, st, s.frame(i))
            out.append((bool(tr.metric.evaluate(r)[0]), f"{r.outcome.value}: {r.reason}"))
            if progress is not None:
                progress()
        return out

    def __call__(self, params: Mapping[str, float]) -> TrialResult:
        tr = self.trial()
        guard = getattr(tr.robot, "reset_guard", None)  # a real arm's reset force watch
        seen = len(guard.peaks) if guard is not None else 0
        timing = getattr(tr.robot, "timing_since", None)  # a real arm's loop timing
        first_tick = tr.robot.ticks if timing is not None else 0
        out = self.outcome(params)
        period = float(tr.robot.control_period)
        sim_s = sum(t.steps for t in out.traces) * period
        info = {
            "success_rate": out.success_rate,
            "wall_s": float(sum(t.wall_s for t in out.traces)),
            "sim_s": sim_s,
        }
        if out.retries:
            info["reflex_retries"] = float(out.retries)
        if guard is not None and len(guard.peaks) > seen:
            info["reset_peak_lateral_n"] = float(max(guard.peaks[seen:]))
            info["reset_handover_lateral_n"] = float(max(guard.handover_peaks[seen:]))
        if timing is not None and len(compute := timing(first_tick)[0]):
            info["loop_p99_us"] = float(np.percentile(compute, 99)) * 1e6
            info["loop_over_1ms"] = float(np.sum(compute > 0.001))
        return TrialResult(out.cost, any(out.successes), info)
