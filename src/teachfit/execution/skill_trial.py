"""A learning trial (Johannsmeier et al. 2019, Sec. V): one parameter set evaluated from several
start poses.

An experiment fixes the task, the estimated hole pose (taught once, with its error) and the
start poses (four slightly different ones) in a :class:`SkillSetup`; each trial then runs the
skill with one set of learned values from every start and reports the mean cost:

    cost = (1 / n) sum_i q_i        (q_i from :class:`~teachfit.execution.metric.LearningMetric`)

:class:`SkillTrial` keeps one robot across trials (building a simulated robot's MuJoCo model
is the slow part) and hands it fresh controller settings (data) at each reset, built from the
adaptive meta-parameters among the learned values. A simulated robot's sensor noise restarts
at each trial from the trial's values (:meth:`SkillTrial.noise_seed`).
"""

from __future__ import annotations

import json
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np

from teachfit.core.geometry import Pose
from teachfit.execution.engine import ExecConfig, ExecutionResult, execute
from teachfit.execution.metric import LearningMetric
from teachfit.robot.interface import restart_noise
from teachfit.robot.registry import make_robot
from teachfit.skills import peg_in_hole
from teachfit.skills.controllers import controller_spec
from teachfit.skills.graph import Skill
from teachfit.tasks.base import Task

V = TypeVar("V")


@dataclass(frozen=True)
class SkillSetup:
    """Everything fixed within an experiment: the skill (context set), the task, the
    estimated hole frame (task frame), the true goal pose and the start poses.

    ``frames``: per start, the task frame the skill runs in (the estimate moved by the task's
    deliberate start deviation, :meth:`~teachfit.tasks.protocols.skill.SkillProtocol.
    start_frames`); empty: ``task2world`` for every start.
    """

    skill: Skill
    task: Task
    task2world: Pose
    goal2world: Pose
    starts: tuple[Pose, ...]
    frames: tuple[Pose, ...] = ()

    def frame(self, i: int) -> Pose:
        """The task frame of start ``i``."""
        return self.frames[i] if self.frames else self.task2world


def peg_in_hole_setup(
    task: Task,
    seed: int | tuple[int, ...] = 0,
    n_starts: int = 4,
    controller: str = "adaptive",
    skill: Skill | None = None,
) -> SkillSetup:
    """The peg-in-hole set-up for ``task``: hole estimate and starts drawn from ``seed`` (an
    integer or a seed sequence, :func:`numpy.random.default_rng`; several set-ups:
    :mod:`teachfit.execution.setups`)."""
    rng = np.random.default_rng(seed)
    base = skill if skill is not None else peg_in_hole.build(controller)
    ctx = peg_in_hole.hole_context(task, rng, base.params.context)
    starts = peg_in_hole.default_starts(task, n_starts, rng)
    deviate = getattr(task.protocol, "start_frames", None)
    frames = tuple(deviate(ctx.hole2world_est, starts)) if callable(deviate) else ()
    return SkillSetup(
        base.with_context(_known(ctx.values, base.params.context))
        .with_fixed(ctx.fixed)
        .with_domains(_known(ctx.domains, base.params.learned), ctx.bound),
        task,
        ctx.hole2world_est,
        ctx.goal2world,
        tuple(starts),
        frames,
    )


def _known(values: Mapping[str, V], names: Mapping[str, object]) -> dict[str, V]:
    """The task's values for the skill's parameters ``names``: a skill written without a
    parameter the task's fit gives (a user's older skill file) runs without it; the task
    gives context and domains, the skill takes those it has."""
    return {k: v for k, v in values.items() if k in names}


@dataclass(frozen=True)
class TrialOutcome:
    """One trial: per-start ``(success, cost)`` and the traces, mean ``cost`` (s); ``retries``
    the executions run again after a safety reflex stopped the arm (once each)."""

    successes: tuple[bool, ...]
    costs: tuple[float, ...]
    traces: tuple[ExecutionResult, ...]
    retries: int = 0

    @property
    def cost(self) -> float:
        return float(np.mean(self.costs))

    @property
    def success_rate(self) -> float:
        return float(np.mean(self.successes))


class SkillTrial:
    """Callable ``learned values -> TrialOutcome`` for one :class:`SkillSetup`.

    Parameters
    ----------
    setup : the experiment's fixed part.
    controller : ``"adaptive"`` (Johannsmeier et al. 2019) or ``"impedance"``.
    metric : defaults to ``LearningMetric(time_limit = the skill's t_max)``.
    config : engine settings.
    robot : name in :data:`~teachfit.robot.registry.ROBOTS`; ``robot_options`` its options.
    seed : the robot's sensor-noise seed.
    """

    def __init__(
        self,
        setup: SkillSetup,
        controller: str = "adaptive",
        metric: LearningMetric | None = None,
        config: ExecConfig | None = None,
        robot: str = "floating",
        seed: int = 0,
        **robot_options: Any,
    ) -> None:
        self.setup = setup
        self.controller = controller
        t_max = setup.skill.params.context.get("t_max")
        self.metric = metric or LearningMetric(time_limit=t_max.value if t_max else 5.0)
        self.config = config or ExecConfig()
        self.robot = make_robot(robot, setup.task, seed=seed, **robot_options)
        self.seed = int(seed)

    def run(
        self, learned: Mapping[str, float] | None, start: Pose, frame: Pose | None = None
    ) -> ExecutionResult:
        """One execution from ``start`` in the task frame ``frame`` (default: the set-up's
        estimate); values validated, defaults fill gaps."""
        s = self.setup
        values = s.skill.resolve(learned)
        return execute(
            s.skill,
            self.robot,
            start,
            s.task2world if frame is None else frame,
            {k: values[k] for k in s.skill.params.learned},
            task=s.task,
            goal2world=s.goal2world,
            config=self.config,
            controller=controller_spec(self.controller, values),
        )

    def noise_seed(self, learned: Mapping[str, float] | None) -> int:
        """The sensor-noise seed of a trial with ``learned`` values: the robot's ``seed`` and
        the values' digest (CRC-32 of their sorted JSON), so that a trial reads the same noise
        whichever trials its worker ran before (a study does not depend on its scheduling)."""
        doc = json.dumps(sorted((k, float(v)) for k, v in (learned or {}).items()))
        return (self.seed << 32) + zlib.crc32(doc.encode())

    def __call__(
        self, learned: Mapping[str, float] | None = None, starts: Sequence[Pose] | None = None
    ) -> TrialOutcome:
        runs: list[tuple[Pose, Pose | None]]
        if starts is None:
            s = self.setup
            runs = [(st, s.frame(i)) for i, st in enumerate(s.starts)]
        else:
            runs = [(st, None) for st in starts]
        restart_noise(self.robot, self.noise_seed(learned))
        traces, retries = [], 0
        for st, fr in runs:
            trace = self.run(learned, st, fr)
            if trace.reflex:  # a reflex stopped the arm: the reset recovers it, one retry
                retries += 1
                trace = self.run(learned, st, fr)
            traces.append(trace)
        scored = [self.metric.evaluate(tr) for tr in traces]
        return TrialOutcome(
            tuple(s for s, _ in scored), tuple(c for _, c in scored), tuple(traces), retries
        )
