"""The execution engine: every skill, search and replay runs through this one loop.

Every command period ``dt`` (``command_rate``; the robot runs its own control law in between,
chosen by the :data:`~teachfit.core.control.ControllerSpec` given at reset) the engine

1. updates the :class:`~teachfit.skills.percept.Percept` from the measured state and the task's
   success detector (``pc.detected``, from the measured TCP pose);
2. checks, in this order, the skill's success condition (stop, ``SUCCESS``), the global and the
   active node's error conditions (stop; ``TIMEOUT`` when only time conditions fired,
   ``FORCE_LIMIT`` when only force conditions did, else ``ERROR_CONDITION``; then the recovery
   node runs), then the active node's transitions (first that holds wins: the node is left,
   the target entered at once, and a ``chain`` target's transitions checked in turn);
3. asks the active primitive for a twist, feed-forward wrench and stiffness (task frame), sends
   the set-point ``(p_d, q_d)`` with them to the robot (world frame) and integrates it,
   ``p_d += v dt``, ``q_d = exp(w dt) q_d``.

A robot fault ends the execution with ``DIVERGED`` (a broken simulation) or ``FAULT``; a
command the controller refuses with ``CONTROL_ERROR``; what was recorded is kept. The result
lists the nodes visited with entry/exit times and why each was left, the first-contact time,
path length and peak force, and a log of pose, wrench, set-point and active node at
``log_rate``. Simulator ground truth (``ground_truth_inserted``) is recorded beside the
measured outcome for benchmarks, clearly named as such.

In the code: :func:`execute` builds a ``_Run`` (one execution's state: the compiled skill,
buffers allocated once, the active node, the log being filled) and calls its steps in turn,
``begin``, ``loop`` (``_stop_condition``, ``_take_transitions``, ``send``, ``advance``) and
``finish`` (``_recover``); ``_ToWorld`` maps a command from the task frame to the world's.
:class:`ExecConfig`, :class:`NodeVisit` and :class:`ExecutionResult` are defined in
:mod:`teachfit.execution.engine_types` and exported here.
"""

from __future__ import annotations

import math
import time

import numpy as np

from teachfit.core.control import ControllerSpec
from teachfit.core.errors import ControlError, ReflexFault, RobotFault, SimulationDiverged
from teachfit.core.geometry import Pose, quat_integrate_into, quat_mul_into
from teachfit.core.outcome import Outcome
from teachfit.core.state import ImpedanceCommand
from teachfit.execution.engine_types import ExecConfig, ExecutionResult, NodeVisit
from teachfit.execution.log import LogBuffer
from teachfit.robot.interface import Robot
from teachfit.skills.conditions import All, Any_, Condition, Detected, ForceAbove, Not, TimeAbove
from teachfit.skills.graph import CompiledNode, Skill
from teachfit.skills.percept import MPCommand, Percept
from teachfit.tasks.base import Task

__all__ = ["ExecConfig", "ExecutionResult", "NodeVisit", "execute"]


def _leaves(cond: Condition) -> tuple[Condition, ...]:
    if isinstance(cond, All):  # Any_ derives from All
        return tuple(c for part in cond.parts for c in _leaves(part))
    if isinstance(cond, Not):
        return _leaves(cond.part)
    return (cond,)


def _uses_detected(skill: Skill) -> bool:
    """Whether any condition of ``skill`` asks for the task's detector (checked per tick then;
    otherwise only at the end: it costs a pose transform per command period)."""
    conds = [skill.success, skill.error, skill.pre]
    conds += [n.error for n in skill.nodes] + [t.condition for t in skill.transitions]
    if skill.recovery is not None:
        conds.append(skill.recovery.error)
    return any(isinstance(c, Detected) for cond in conds if cond for c in _leaves(cond))


def _classify(fired: list[Condition]) -> Outcome:
    """The outcome named by the kind of error conditions that fired."""
    leaves = [c for cond in fired for c in _leaves(cond)]
    if leaves and all(isinstance(c, TimeAbove) for c in leaves):
        return Outcome.TIMEOUT
    if leaves and all(isinstance(c, ForceAbove) for c in leaves):
        return Outcome.FORCE_LIMIT
    return Outcome.ERROR_CONDITION


def _fault_outcome(exc: Exception) -> Outcome:
    if isinstance(exc, SimulationDiverged):
        return Outcome.DIVERGED
    if isinstance(exc, RobotFault):
        return Outcome.FAULT
    return Outcome.CONTROL_ERROR


def _holding(cond: Condition, values: dict[str, float], pc: Percept) -> tuple[str, list]:
    """The parts of an (``any``-)condition that hold now: described, and themselves."""
    parts = cond.parts if isinstance(cond, Any_) else (cond,)
    held = [c for c in parts if c.compile(values)(pc)]
    text = " ∨ ".join(c.describe() for c in held) if held else cond.describe()
    return text, held or [cond]


def execute(
    skill: Skill,
    robot: Robot,
    start: Pose,
    task2world: Pose,
    learned: dict[str, float] | None = None,
    *,
    task: Task | None = None,
    goal2world: Pose | None = None,
    config: ExecConfig | None = None,
    controller: ControllerSpec | None = None,
) -> ExecutionResult:
    """Reset ``robot`` at ``start`` (running ``controller``; ``None`` keeps its law) and run
    ``skill`` with ``learned`` values (defaults for missing names) in the task frame
    ``task2world``; see the module docstring.

    ``task`` provides the success detector (and the ground truth recorded beside it);
    ``goal2world`` is where the TCP should end (default: the task frame's origin). Invalid
    parameter values raise :class:`SkillError` before the robot moves.
    """
    run = _Run(skill, robot, task2world, learned, task, goal2world, config or ExecConfig())
    run.begin(start, controller)
    if run.outcome is not Outcome.PRECONDITION:
        run.loop()
    return run.finish()


def _enter(node: CompiledNode, pc: Percept) -> None:
    """Enter ``node``: its clock at 0, no goal yet, the set-point held where the part is
    (unless the node keeps the previous one, or its orientation), its primitive told."""
    pc.t_node = 0.0
    pc.goal[:] = math.nan
    if node.reset_setpoint:
        pc.hold_here(position_only=node.keep_orientation)
    node.run.enter(pc)


class _ToWorld:
    """Turns a primitive's command (task frame) into the robot's order (world frame), with
    the rotation ``rot`` (task -> world, (3, 3)); its buffers are allocated once."""

    def __init__(self, rot: np.ndarray) -> None:
        self.rot = rot
        self.k_w = np.zeros((6, 6))  # a full stiffness in the world frame
        self.blk = np.zeros((6, 6))  # diag(rot, rot)
        self.blk[:3, :3] = rot
        self.blk[3:, 3:] = rot
        # the bytes of the last diagonal task-frame k and its world-frame (6, 6), read-only
        self.k_key, self.k_diag = b"", self.k_w

    def order(
        self, cmd: MPCommand, pos_w: np.ndarray, quat_w: np.ndarray, ff: np.ndarray
    ) -> ImpedanceCommand:
        """The order for set-point ``(pos_w, quat_w)`` and world feed-forward ``ff``."""
        rot = self.rot
        v, w = cmd.twist[:3], cmd.twist[3:]
        if cmd.full:
            k_w = self.k_w
            np.dot(self.blk, cmd.stiffness_full, out=k_w)
            k_w[:] = k_w @ self.blk.T
            return ImpedanceCommand(
                pos=pos_w, quat=quat_w, lin_vel=rot @ v, ang_vel=rot @ w, wrench_ff=ff,
                stiffness=k_w,
            )  # fmt: skip
        # R diag(k) R^T per block: PSD by construction, the general checks skipped; built
        # once per distinct k (a primitive holds its gains for many commands)
        k = cmd.stiffness
        key = k.tobytes()
        if key != self.k_key:
            k_new = np.zeros((6, 6))
            k_new[:3, :3] = (rot * k[:3]) @ rot.T
            k_new[3:, 3:] = (rot * k[3:]) @ rot.T
            k_new.setflags(write=False)
            self.k_key, self.k_diag = key, k_new
        return ImpedanceCommand.from_diagonal_frame(
            pos_w, quat_w, np.dot(rot, v), np.dot(rot, w), ff, self.k_diag, k
        )


class _Run:
    """One execution in progress: the compiled skill, the buffers (allocated once), the
    active node, the statistics and the log being filled, and how it ended so far.

    The steps: :meth:`begin` (reset, precondition, start node), :meth:`loop` (command
    periods until it stops), :meth:`finish` (the end state, recovery, the result).
    """

    def __init__(
        self,
        skill: Skill,
        robot: Robot,
        task2world: Pose,
        learned: dict[str, float] | None,
        task: Task | None,
        goal2world: Pose | None,
        cfg: ExecConfig,
    ) -> None:
        self.skill, self.robot, self.task, self.cfg = skill, robot, task, cfg
        self.nodes, self.recovery, self.success, self.error, self.pre = skill.compile(learned)
        self.values = skill.resolve(learned)
        self.names = tuple(n.name for n in self.nodes)
        period = robot.control_period
        self.ticks = max(1, round(1.0 / (cfg.command_rate * period)))  # control ticks
        self.dt = self.ticks * period  # s per command
        self.log_every = max(1, round(1.0 / (cfg.log_rate * self.dt)))  # commands per row
        self.pc = Percept(task2world, self.dt)
        self.goal = goal2world.pos if goal2world is not None else task2world.pos
        rows = math.ceil((cfg.max_time + cfg.recovery_time) / (self.dt * self.log_every))
        self.log = LogBuffer(int(rows) + 4)
        self.cmd = MPCommand()
        self.to_world = _ToWorld(self.pc.rot)
        self.sp_pos, self.sp_ff, self.sp_quat = np.zeros(3), np.zeros(6), np.zeros(4)
        self.dq, self.qtmp = np.zeros(4), np.zeros(4)
        self.last_pos = np.zeros(3)  # the last finite TCP position (world)
        uses = task is not None and _uses_detected(skill)
        self.detect = task.detect_success if task is not None and uses else None
        self.t0 = 0.0  # the robot's clock at the reset
        self.visits: list[NodeVisit] = []
        self.t_contact = self.t_success = math.nan
        self.path = self.peak = 0.0
        self.steps = 0
        self.idx = self.names.index(skill.start)
        self.active = self.nodes[self.idx]
        self.t_enter = 0.0
        self.outcome, self.reason = Outcome.TIMEOUT, f"hard cap of {cfg.max_time:g} s"
        self.faulted = self.by_error = self.reflex = False
        self.wall0 = time.perf_counter()

    def begin(self, start: Pose, controller: ControllerSpec | None) -> None:
        """Reset the robot at ``start`` with the set-point there; check the precondition,
        enter the start node if it holds; log the first row."""
        state = self.robot.reset(start, controller)
        self.t0 = state.t
        pc = self.pc
        pc.update(state, 0.0)
        pc.detected = bool(self.detect(state.pose)) if self.detect is not None else False
        pc.hold_here()
        self.last_pos[:] = pc.pos
        self.sp_pos[:] = pc.pos
        self.sp_quat[:] = pc.quat
        if self.pre is not None and not self.pre(pc):
            self.outcome, self.reason = Outcome.PRECONDITION, "precondition does not hold"
        else:
            self.active.run.enter(pc)
        self.log.add(0.0, state, pc.depth, self.sp_pos, self.sp_ff, self.idx, self.sp_quat)

    def loop(self) -> None:
        """Command periods until success, an error condition, the hard cap or a fault."""
        pc, cmd = self.pc, self.cmd
        while not self._stop_condition():
            self._take_transitions()
            if pc.t >= self.cfg.max_time:
                return  # the hard cap: the TIMEOUT set at the start
            cmd.clear()
            self.active.run.command(pc, cmd)
            try:
                self.send()
                self.advance(self.idx)
            except (RobotFault, ControlError) as exc:
                self.outcome, self.reason, self.faulted = _fault_outcome(exc), f"{exc}", True
                self.reflex = isinstance(exc, ReflexFault)
                return

    def _stop_condition(self) -> bool:
        """Whether the success condition or an error condition (global or the active
        node's, both evaluated) holds now; sets the outcome and reason if so."""
        pc, active = self.pc, self.active
        if self.success(pc):
            self.outcome, self.reason, self.t_success = Outcome.SUCCESS, "success condition", pc.t
            return True
        glob, local = self.error(pc), active.error(pc)
        if not (glob or local):
            return False
        cond = self.skill.error if glob else self.skill.node(active.name).error
        which, held = _holding(cond, self.values, pc)  # type: ignore[arg-type]
        self.outcome, self.by_error = _classify(held), True
        self.reason = f"{'skill' if glob else active.name} error: {which}"
        return True

    def _take_transitions(self) -> None:
        """Leave the active node by its first transition that holds and enter the target; a
        ``chain`` node entered checks its own transitions at once (at most once per node)."""
        pc = self.pc
        for _ in self.names:
            active = self.active
            fired = next(((t, d) for check, t, d in active.transitions if check(pc)), None)
            if fired is None:
                return
            target, desc = fired
            reason = f"-> {self.names[target]}: {desc}"
            self.visits.append(NodeVisit(active.name, self.t_enter, pc.t, reason))
            active.run.leave(pc)
            self.idx, self.active, self.t_enter = target, self.nodes[target], pc.t
            _enter(self.active, pc)
            if not self.active.chain:
                return

    def send(self) -> None:
        """Command the set-point for the coming period and integrate it (task -> world):
        ``p_d += v dt``, ``q_d = exp(w dt) q_d``."""
        pc, cmd, dt, rot = self.pc, self.cmd, self.dt, self.pc.rot
        v, w = cmd.twist[:3], cmd.twist[3:]
        pos_w, quat_w = pc.to_world_pose(pc.p_d, pc.q_d)
        ff = np.empty(6)  # a fresh array: the command keeps it
        # np.dot: the same BLAS product as ``@`` (same bits), with less dispatch per command
        np.dot(rot, cmd.wrench[:3], out=ff[:3])
        np.dot(rot, cmd.wrench[3:], out=ff[3:])
        self.robot.command(self.to_world.order(cmd, pos_w, quat_w, ff))
        self.sp_pos[:] = pos_w
        self.sp_quat[:] = quat_w
        self.sp_ff[:] = ff
        pc.p_d += v * dt
        if w[0] != 0.0 or w[1] != 0.0 or w[2] != 0.0:
            dq, qtmp = self.dq, self.qtmp
            dq[:] = (1.0, 0.0, 0.0, 0.0)
            quat_integrate_into(dq, w, dt)  # exp(w dt)
            quat_mul_into(qtmp, dq, pc.q_d)  # a task-frame angular velocity: left product
            pc.q_d[:] = qtmp / math.sqrt(float(qtmp @ qtmp))

    def advance(self, node_index: int) -> None:
        """Step the robot one command period, update the percept, the first-contact time,
        path length and peak force, and log a row every ``log_every`` commands as node
        ``node_index`` (may raise :class:`RobotFault`)."""
        st = self.robot.step(self.ticks)
        self.steps += self.ticks
        t = st.t - self.t0
        pc = self.pc
        pc.update(st, t)
        pc.t_node = t - self.t_enter  # from the entry of the node running (recovery's too)
        if not math.isfinite(sum(pc.p.tolist()) + sum(pc.f.tolist())):  # NaN/inf propagate
            raise SimulationDiverged(f"non-finite state at t={t:.3f} s")
        pc.detected = bool(self.detect(st.pose)) if self.detect is not None else False
        step = pc.pos - self.last_pos
        self.path += math.sqrt(float(step.dot(step)))  # = np.linalg.norm, less dispatch
        self.last_pos[:] = pc.pos
        force = math.hypot(*st.wrench[:3].tolist())
        self.peak = max(self.peak, force)
        if math.isnan(self.t_contact) and force >= self.cfg.contact_force:
            self.t_contact = t
        if (self.steps // self.ticks) % self.log_every == 0:
            self.log.add(t, st, pc.depth, self.sp_pos, self.sp_ff, node_index, self.sp_quat)

    def finish(self) -> ExecutionResult:
        """Close the last visit, judge the end state, run the recovery node after an error
        condition, and build the result."""
        t_end = self.pc.t
        recovery = self.recovery if self.by_error and self.cfg.recovery_time > 0 else None
        if recovery is None:  # a real arm's loop runs on: the skill's press ends now
            self.robot.finish_execution()
        if self.outcome is not Outcome.PRECONDITION:
            self.visits.append(NodeVisit(self.active.name, self.t_enter, t_end, self.reason))
        remaining = float(np.linalg.norm(self.last_pos - self.goal))
        detected, truth = self._judge_end()
        if recovery is not None:
            self.visits.append(self._recover(recovery))
            self.robot.finish_execution()
        return ExecutionResult(
            skill=self.skill.name,
            outcome=self.outcome,
            reason=self.reason,
            visits=tuple(self.visits),
            t_first_contact=self.t_contact,
            t_end=t_end,
            time_to_success=self.t_success,
            path_length=self.path,
            peak_force=self.peak,
            remaining=remaining,
            detected=detected,
            ground_truth_inserted=truth,
            log=self.log.freeze(),
            node_names=self.names,
            steps=self.steps,
            wall_s=time.perf_counter() - self.wall0,
            reflex=self.reflex,
        )

    def _judge_end(self) -> tuple[bool | None, bool | None]:
        """The task's detector and (unless the robot faulted) its ground truth at the last
        finite pose; ``None`` without a task or a finite orientation."""
        pc, task = self.pc, self.task
        final = Pose(self.last_pos, pc.quat) if np.all(np.isfinite(pc.quat)) else None
        if task is None or final is None:
            return None, None
        detected = bool(task.detect_success(final))
        return detected, None if self.faulted else bool(task.ground_truth_inserted(final))

    def _recover(self, node: CompiledNode) -> NodeVisit:
        """Run the recovery node for at most ``cfg.recovery_time`` (a fault ends it)."""
        pc, cmd = self.pc, self.cmd
        t_enter = self.t_enter = pc.t  # the recovery's clock (``advance`` sets ``t_node``)
        _enter(node, pc)
        why = "recovered"
        try:
            while (
                pc.t_node < self.cfg.recovery_time
                and not node.error(pc)
                and not (pc.done and pc.t_node > 0)
            ):
                cmd.clear()
                node.run.command(pc, cmd)
                self.send()
                self.advance(-1)
        except (RobotFault, ControlError) as exc:
            why = f"{_fault_outcome(exc).value}: {exc}"
        return NodeVisit(node.name, t_enter, pc.t, why)
