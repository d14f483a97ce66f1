"""Executing skills in simulation: peg-in-hole on peg2d, the cost metric, divergence."""

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import pytest

from teachfit.core.errors import SimulationDiverged
from teachfit.core.geometry import Pose
from teachfit.core.outcome import Outcome
from teachfit.execution.engine import ExecConfig, execute
from teachfit.execution.metric import LearningMetric
from teachfit.execution.skill_trial import SkillTrial, peg_in_hole_setup
from teachfit.robot.floating import FloatingToolRobot
from teachfit.skills import peg_in_hole
from teachfit.skills.conditions import TimeAbove
from teachfit.skills.graph import Node, Skill, Transition
from teachfit.skills.params import SkillParams
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.primitive import Primitive, PrimitiveRun
from teachfit.tasks import Peg2D

ORDER = ["approach", "contact", "lateral", "align", "insert"]


@pytest.fixture(scope="module")
def task():
    return Peg2D()


def _with_error(setup, dx, dy):
    """The set-up with the hole estimate off the true hole by (dx, dy) m."""
    est = setup.task.hole2world.compose(Pose.from_xyz_rz(dx, dy, 0.0))
    return dataclasses.replace(setup, task2world=est)


@pytest.mark.parametrize("controller", ["adaptive", "impedance"])
def test_default_skill_inserts_despite_hole_pose_error(task, controller):
    setup = _with_error(peg_in_hole_setup(task, seed=1, controller=controller), 8e-4, -6e-4)
    trial = SkillTrial(setup, controller=controller, seed=1)
    out = trial(starts=setup.starts[:2])
    assert out.successes == (True, True), [tr.reason for tr in out.traces]
    for tr, cost in zip(out.traces, out.costs, strict=True):
        visited = [v.node for v in tr.visits]
        assert visited[0] == "approach" and visited == ORDER[: len(visited)]
        assert len(visited) >= 4 and tr.detected and tr.ground_truth_inserted
        assert 0.0 < tr.t_first_contact < tr.t_end < 5.0
        assert cost == pytest.approx(tr.t_end - tr.t_first_contact)
        assert all(
            a.t_exit == pytest.approx(b.t_enter)
            for a, b in zip(tr.visits, tr.visits[1:], strict=False)
        )
        assert tr.steps == pytest.approx(tr.t_end * 1000, abs=15)
        assert tr.log.t.size > 50 and np.all(np.diff(tr.log.t) > 0)
    assert out.success_rate == 1.0 and out.cost == pytest.approx(np.mean(out.costs))


def test_failure_costs_limit_plus_factor_times_remaining(task):
    # estimate 6 mm off: the part lands beside the hole and cannot be inserted
    setup = _with_error(peg_in_hole_setup(task, seed=2, controller="impedance"), 6e-3, 0.0)
    setup = dataclasses.replace(setup, skill=setup.skill.with_context({"t_max": 1.6}))
    trial = SkillTrial(
        setup, controller="impedance", metric=LearningMetric(time_limit=1.6, distance_factor=100.0)
    )
    out = trial(starts=setup.starts[:1])
    tr = out.traces[0]
    assert not out.successes[0] and tr.outcome is Outcome.TIMEOUT  # the t_max error exit
    assert tr.detected is False and tr.ground_truth_inserted is False
    truth = setup.goal2world.pos
    assert tr.remaining > 0.004
    assert tr.remaining == pytest.approx(
        np.linalg.norm(tr.log.pos[tr.log.t <= tr.t_end][-1] - truth), abs=2e-3
    )
    assert out.costs[0] == pytest.approx(1.6 + 100.0 * tr.remaining)
    assert tr.visits[-1].node == "retract"  # the recovery node ran after the error
    # ... on its own clock: the last node ran for over a second, the retract still gets its
    # 0.5 s budget (or ends at its goal, 10 mm up) instead of one command period
    rec = tr.visits[-1]
    assert tr.visits[-2].t_exit - tr.visits[-2].t_enter > 0.5
    assert rec.t_exit - rec.t_enter > 0.1
    lifted = (
        tr.log.pos[tr.log.t >= rec.t_exit - 1e-9][0, 2] - tr.log.pos[tr.log.t <= rec.t_enter][-1, 2]
    )
    assert lifted > 0.003
    assert LearningMetric(1.6, 100.0).evaluate(tr) == (False, out.costs[0])


class _Exploding(FloatingToolRobot):
    """A simulated robot whose state turns to NaN after ``after`` control ticks."""

    def __init__(self, *args, after: int, **kwargs):
        super().__init__(*args, **kwargs)
        self.after, self.ticks = after, 0

    def step(self, n=1):
        self.ticks += n
        if self.ticks > self.after:
            self.data.qvel[0] = math.nan
        return super().step(n)


def test_diverging_simulation_fails_the_execution_without_raising(task):
    setup = peg_in_hole_setup(task, seed=0, controller="impedance")
    robot = _Exploding(task, after=300)
    with pytest.raises(SimulationDiverged):  # the robot itself does raise ...
        robot.reset(setup.starts[0])
        robot.ticks = 10_000
        robot.step(1)
    robot.ticks = 0
    tr = execute(
        setup.skill,
        robot,
        setup.starts[0],
        setup.task2world,
        task=task,
        goal2world=setup.goal2world,
    )  # ... the execution does not
    assert tr.outcome is Outcome.DIVERGED and not tr.success and "simulation invalid" in tr.reason
    assert tr.t_end == pytest.approx(0.3, abs=0.02) and math.isfinite(tr.remaining)
    ok, cost = LearningMetric().evaluate(tr)
    assert not ok and math.isfinite(cost) and cost > LearningMetric().time_limit


def test_precondition_blocks_the_start(task):
    setup = peg_in_hole_setup(task, seed=0, controller="impedance")
    skill = dataclasses.replace(setup.skill, pre=TimeAbove(1.0, scope="skill"))
    robot = FloatingToolRobot(task)
    tr = execute(
        skill,
        robot,
        setup.starts[0],
        setup.task2world,
        task=task,
        config=ExecConfig(recovery_time=0.0),
    )
    assert tr.outcome is Outcome.PRECONDITION and tr.steps == 0 and tr.visits == ()


def test_peg_in_hole_context_from_task(task):
    rng = np.random.default_rng(0)
    ctx = peg_in_hole.hole_context(task, rng)
    assert ctx.values["depth"] == pytest.approx(task.success_depth + 5e-4)
    off = ctx.hole2world_est.pos - task.hole2world.pos
    assert 0 < np.hypot(*off[:2]) < 0.004  # a realistic, sub-4-mm taught error
    starts = peg_in_hole.default_starts(task, 4, rng)
    assert len(starts) == 4 and all(s.pos[2] > task.surface_z + 0.02 for s in starts)


def test_the_fast_command_path_leaves_an_execution_unchanged(task, monkeypatch):
    """A task frame yawed off the world: the engine's task-frame stiffness is a full (6, 6)
    matrix; its unchecked command and the remembered damping give the very same execution
    as the checked constructor and a fresh ``critical_damping`` every command."""
    from teachfit.control import impedance
    from teachfit.core.state import ImpedanceCommand

    setup = peg_in_hole_setup(task, seed=1, controller="adaptive")
    est = setup.task.hole2world.compose(Pose.from_xyz_rz(8e-4, -6e-4, 0.0, 0.4))
    setup = dataclasses.replace(setup, task2world=est)
    trial = SkillTrial(setup, controller="adaptive", seed=1)
    fast = trial(starts=setup.starts[:1]).traces[0]
    monkeypatch.setattr(
        ImpedanceCommand, "from_diagonal_frame", lambda *a: ImpedanceCommand(*a[:6])
    )
    monkeypatch.setattr(
        impedance.DampingMemo,
        "__call__",
        lambda self, k, r: impedance.critical_damping(k, self.mass, r),
    )
    ref = SkillTrial(setup, controller="adaptive", seed=1)(starts=setup.starts[:1]).traces[0]
    assert fast.outcome == ref.outcome and fast.steps == ref.steps > 100
    for name in ("pos", "quat", "wrench", "setpoint_pos"):
        assert np.array_equal(getattr(fast.log, name), getattr(ref.log, name)), name


@dataclass(frozen=True)
class _Noting(Primitive):
    """Holds the set-point; notes the skill time (s) in ``left`` whenever its node is left."""

    left: list[float] = field(default_factory=list)
    kind: ClassVar[str] = "noting"

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        return _NotingRun(self.left)

    def describe(self) -> str:
        return "hold, note leaving"


class _NotingRun(PrimitiveRun):
    def __init__(self, left: list[float]) -> None:
        self.left = left

    def enter(self, pc: Percept) -> None:
        pc.done = False

    def command(self, pc: Percept, out: MPCommand) -> None:
        out.stiffness[:] = (2000.0, 2000.0, 2000.0, 60.0, 60.0, 60.0)

    def leave(self, pc: Percept) -> None:
        self.left.append(pc.t)


def test_a_chain_node_checks_its_transitions_on_entry_and_a_left_node_hears_of_it(task):
    still = _Noting()
    err = TimeAbove(2.0)
    nodes = [Node("a", still, err), Node("b", still, err, chain=True), Node("c", still, err)]
    nodes.append(Node("d", still, err))
    skill = Skill(
        "chain",
        nodes,
        (
            Transition("a", "b", TimeAbove(0.05)),
            Transition("b", "c", TimeAbove(0.0)),  # holds at once: left in the same command
            Transition("c", "d", TimeAbove(0.0)),  # c is no chain node: checked a command on
        ),
        "a",
        SkillParams(),
        success=TimeAbove(0.2, scope="skill"),
        error=TimeAbove(1.0, scope="skill"),
    )
    start = task.contact_pose(np.array([0.02, 0.0])).compose(Pose.from_xyz_rz(0, 0, 0.01, 0))
    tr = execute(skill, FloatingToolRobot(task), start, Pose(np.zeros(3)), config=ExecConfig())
    (a, b, c, d) = tr.visits
    assert [v.node for v in tr.visits] == ["a", "b", "c", "d"]
    assert b.t_enter == b.t_exit == c.t_enter  # the chain node was left as it was entered
    assert d.t_enter == pytest.approx(c.t_enter + 0.01)  # one command later
    assert still.left == [a.t_exit, b.t_exit, c.t_exit]  # each node left by a transition was told


@dataclass(frozen=True)
class _Turning(Primitive):
    """Sets the orientation set-point to ``yaw`` (rad, about the task z; 0: leaves it), free in
    rotation; notes (q_d, q) whenever its node is entered, after the engine set the set-point."""

    yaw: float = 0.0
    entered: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    kind: ClassVar[str] = "turning"

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        return _TurningRun(self.yaw, self.entered)

    def describe(self) -> str:
        return "turn, note entering"


class _TurningRun(PrimitiveRun):
    def __init__(self, yaw: float, entered: list[tuple[np.ndarray, np.ndarray]]) -> None:
        self.yaw, self.entered = yaw, entered

    def enter(self, pc: Percept) -> None:
        self.entered.append((pc.q_d.copy(), pc.q.copy()))
        pc.done = False

    def command(self, pc: Percept, out: MPCommand) -> None:
        if self.yaw:
            pc.q_d[:] = (math.cos(self.yaw / 2), 0.0, 0.0, math.sin(self.yaw / 2))
        out.twist[:] = 0.0
        out.stiffness[:] = (2000.0, 2000.0, 2000.0, 0.0, 0.0, 0.0)


def test_a_node_that_keeps_its_orientation_starts_from_the_commanded_one(task):
    noted: list[tuple[np.ndarray, np.ndarray]] = []
    err = TimeAbove(2.0)
    nodes = (
        Node("turn", _Turning(0.3), err),
        Node("keep", _Turning(0.0, noted), err, keep_orientation=True),
        Node("reset", _Turning(0.0, noted), err),
    )
    skill = Skill(
        "keep",
        nodes,
        (Transition("turn", "keep", TimeAbove(0.3)), Transition("keep", "reset", TimeAbove(0.0))),
        "turn",
        SkillParams(),
        success=TimeAbove(0.4, scope="skill"),
        error=TimeAbove(1.0, scope="skill"),
    )
    start = task.contact_pose(np.array([0.02, 0.0])).compose(Pose.from_xyz_rz(0, 0, 0.01, 0))
    execute(skill, FloatingToolRobot(task), start, Pose(np.zeros(3)), config=ExecConfig())
    (qd_keep, q_keep), (qd_reset, q_reset) = noted
    assert 2 * math.atan2(q_keep[3], q_keep[0]) == pytest.approx(0.0, abs=0.01)  # not turned
    np.testing.assert_allclose(qd_keep, (math.cos(0.15), 0.0, 0.0, math.sin(0.15)), atol=1e-9)
    np.testing.assert_allclose(qd_reset, q_reset)  # the default: from the measured pose
