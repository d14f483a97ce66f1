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
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from teachfit.core.control import ControllerSpec
from teachfit.core.errors import ControlError, RobotFault, SimulationDiverged, SkillError
from teachfit.core.geometry import Pose, quat_integrate_into, quat_mul_into
from teachfit.core.outcome import Outcome
from teachfit.core.state import ImpedanceCommand
from teachfit.execution.log import ExecutionLog, LogBuffer
from teachfit.robot.interface import Robot
from teachfit.skills.conditions import (
    All,
    Any_,
    Condition,
    Detected,
    ForceAbove,
    Not,
    TimeAbove,
)
from teachfit.skills.graph import Skill
from teachfit.skills.percept import MPCommand, Percept
from teachfit.tasks.base import Task


@dataclass(frozen=True)
class ExecConfig:
    """Engine settings: ``command_rate`` and ``log_rate`` (Hz); ``contact_force`` (N) marks
    first contact; ``max_time`` (s) is a hard cap besides the skill's own error condition;
    ``recovery_time`` (s) bounds the recovery node (0: skip recovery)."""

    command_rate: float = 100.0
    log_rate: float = 100.0
    contact_force: float = 2.0
    max_time: float = 30.0
    recovery_time: float = 0.5

    def __post_init__(self) -> None:
        if not 1.0 <= self.command_rate <= 1000.0:
            raise SkillError("command_rate must be within [1, 1000] Hz")
        if not 0 < self.log_rate <= self.command_rate:
            raise SkillError("log_rate must be within (0, command_rate]")
        if not (self.contact_force > 0 and self.max_time > 0 and self.recovery_time >= 0):
            raise SkillError("contact_force and max_time must be > 0, recovery_time >= 0")


@dataclass(frozen=True)
class NodeVisit:
    """One stay in a node: ``t_enter``, ``t_exit`` (s since the start), why it ended."""

    node: str
    t_enter: float
    t_exit: float
    reason: str


@dataclass(frozen=True)
class ExecutionResult:
    """What one execution did (times in s since the execution started).

    ``outcome`` says why it stopped and ``reason`` in words; ``time_to_success`` is NaN unless
    it succeeded; ``remaining`` (m) the TCP's distance to ``goal2world`` at the end (the last
    finite state if the simulation diverged); ``detected`` the task's success detector at the
    end (``None`` without a task); ``ground_truth_inserted`` the simulator's ground truth then
    (``None`` without a task or after a fault), for benchmarks only.
    """

    skill: str
    outcome: Outcome
    reason: str
    visits: tuple[NodeVisit, ...]
    t_first_contact: float
    t_end: float
    time_to_success: float
    path_length: float
    peak_force: float
    remaining: float
    detected: bool | None
    ground_truth_inserted: bool | None
    log: ExecutionLog
    node_names: tuple[str, ...]
    steps: int
    wall_s: float

    @property
    def success(self) -> bool:
        """The success condition fired (and, with a task, its detector agrees)."""
        return self.outcome is Outcome.SUCCESS and self.detected is not False

    @property
    def duration(self) -> float:
        return self.t_end


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
    cfg = config or ExecConfig()
    nodes, recovery, success, error, pre = skill.compile(learned)
    values = skill.resolve(learned)
    names = tuple(n.name for n in nodes)
    period = robot.control_period
    ticks = max(1, round(1.0 / (cfg.command_rate * period)))
    dt = ticks * period
    log_every = max(1, round(1.0 / (cfg.log_rate * dt)))
    pc = Percept(task2world, dt)
    goal = goal2world.pos if goal2world is not None else task2world.pos
    log = LogBuffer(int(math.ceil((cfg.max_time + cfg.recovery_time) / (dt * log_every))) + 4)
    cmd = MPCommand()
    rot = pc.rot
    k_w = np.zeros((6, 6))
    k_frame: list = [b"", k_w]  # (bytes of the task-frame k, its world-frame (6, 6), read-only)
    blk = np.zeros((6, 6))
    blk[:3, :3] = rot
    blk[3:, 3:] = rot
    sp_pos, sp_ff, sp_quat = np.zeros(3), np.zeros(6), np.zeros(4)
    dq, qtmp = np.zeros(4), np.zeros(4)
    last_pos = np.zeros(3)  # the last finite TCP position (world)
    detect = task.detect_success if task is not None and _uses_detected(skill) else None
    wall0 = time.perf_counter()

    state = robot.reset(start, controller)
    t0 = state.t
    pc.update(state, 0.0)
    pc.detected = bool(detect(state.pose)) if detect is not None else False
    pc.hold_here()
    last_pos[:] = pc.pos
    sp_pos[:] = pc.pos
    sp_quat[:] = pc.quat
    visits: list[NodeVisit] = []
    t_contact = math.nan
    t_success = math.nan
    path = peak = 0.0
    steps = 0
    idx = names.index(skill.start)
    active = nodes[idx]
    t_enter = 0.0
    outcome, reason = Outcome.TIMEOUT, f"hard cap of {cfg.max_time:g} s"
    running = True
    if pre is not None and not pre(pc):
        outcome, reason, running = Outcome.PRECONDITION, "precondition does not hold", False
    else:
        active.run.enter(pc)

    def send() -> None:
        """Command the set-point for the coming period and integrate it (task -> world)."""
        v, w = cmd.twist[:3], cmd.twist[3:]
        pos_w, quat_w = pc.to_world_pose(pc.p_d, pc.q_d)
        ff = np.concatenate([rot @ cmd.wrench[:3], rot @ cmd.wrench[3:]])
        if cmd.full:
            np.dot(blk, cmd.stiffness_full, out=k_w)
            k_w[:] = k_w @ blk.T
            order = ImpedanceCommand(
                pos=pos_w, quat=quat_w, lin_vel=rot @ v, ang_vel=rot @ w, wrench_ff=ff,
                stiffness=k_w,
            )  # fmt: skip
        else:  # R diag(k) R^T per block: PSD by construction, the general checks skipped;
            # built once per distinct k (a primitive holds its gains for many commands)
            k = cmd.stiffness
            key = k.tobytes()
            if key != k_frame[0]:
                k_new = np.zeros((6, 6))
                k_new[:3, :3] = (rot * k[:3]) @ rot.T
                k_new[3:, 3:] = (rot * k[3:]) @ rot.T
                k_new.setflags(write=False)
                k_frame[:] = key, k_new
            order = ImpedanceCommand.from_diagonal_frame(
                pos_w, quat_w, rot @ v, rot @ w, ff, k_frame[1], k
            )
        robot.command(order)
        sp_pos[:] = pos_w
        sp_quat[:] = quat_w
        sp_ff[:] = ff
        pc.p_d += v * dt
        if w[0] != 0.0 or w[1] != 0.0 or w[2] != 0.0:
            dq[:] = (1.0, 0.0, 0.0, 0.0)
            quat_integrate_into(dq, w, dt)  # exp(w dt)
            quat_mul_into(qtmp, dq, pc.q_d)  # a task-frame angular velocity: left product
            pc.q_d[:] = qtmp / math.sqrt(float(qtmp @ qtmp))

    def advance(node_index: int) -> None:
        """Step the robot one command period and update the percept (may raise)."""
        nonlocal steps, t_contact, path, peak
        st = robot.step(ticks)
        steps += ticks
        t = st.t - t0
        pc.update(st, t)
        pc.t_node = t - t_enter
        if not math.isfinite(sum(pc.p.tolist()) + sum(pc.f.tolist())):  # NaN/inf propagate
            raise SimulationDiverged(f"non-finite state at t={t:.3f} s")
        pc.detected = bool(detect(st.pose)) if detect is not None else False
        path += float(np.linalg.norm(pc.pos - last_pos))
        last_pos[:] = pc.pos
        force = math.hypot(*st.wrench[:3])
        peak = max(peak, force)
        if math.isnan(t_contact) and force >= cfg.contact_force:
            t_contact = t
        if (steps // ticks) % log_every == 0:
            log.add(t, st, pc.depth, sp_pos, sp_ff, node_index, sp_quat)

    log.add(0.0, state, pc.depth, sp_pos, sp_ff, idx, sp_quat)
    faulted = by_error = False
    while running:
        if success(pc):
            outcome, reason, t_success = Outcome.SUCCESS, "success condition", pc.t
            break
        glob, local = error(pc), active.error(pc)
        if glob or local:
            cond = skill.error if glob else skill.node(active.name).error
            which, held = _holding(cond, values, pc)  # type: ignore[arg-type]
            outcome, by_error = _classify(held), True
            reason = f"{'skill' if glob else active.name} error: {which}"
            break
        for _ in names:  # a `chain` node entered checks its own transitions at once
            fired = next(((t, d) for check, t, d in active.transitions if check(pc)), None)
            if fired is None:
                break
            target, desc = fired
            visits.append(NodeVisit(active.name, t_enter, pc.t, f"-> {names[target]}: {desc}"))
            active.run.leave(pc)
            idx, active, t_enter = target, nodes[target], pc.t
            pc.t_node = 0.0
            pc.goal[:] = math.nan
            if active.reset_setpoint:
                pc.hold_here()
            active.run.enter(pc)
            if not active.chain:
                break
        if pc.t >= cfg.max_time:
            break
        cmd.clear()
        active.run.command(pc, cmd)
        try:
            send()
            advance(idx)
        except (RobotFault, ControlError) as exc:
            outcome, reason, faulted = _fault_outcome(exc), f"{exc}", True
            break
    t_end = pc.t
    if outcome is not Outcome.PRECONDITION:
        visits.append(NodeVisit(active.name, t_enter, t_end, reason))
    remaining = float(np.linalg.norm(last_pos - goal))
    final = Pose(last_pos, pc.quat) if np.all(np.isfinite(pc.quat)) else None
    detected = None if task is None or final is None else bool(task.detect_success(final))
    truth = None
    if task is not None and final is not None and not faulted:
        truth = bool(task.ground_truth_inserted(final))
    if by_error and recovery is not None and cfg.recovery_time > 0:
        visits.append(_recover(recovery, pc, cmd, cfg, send, advance))
    return ExecutionResult(
        skill=skill.name,
        outcome=outcome,
        reason=reason,
        visits=tuple(visits),
        t_first_contact=t_contact,
        t_end=t_end,
        time_to_success=t_success,
        path_length=path,
        peak_force=peak,
        remaining=remaining,
        detected=detected,
        ground_truth_inserted=truth,
        log=log.freeze(),
        node_names=names,
        steps=steps,
        wall_s=time.perf_counter() - wall0,
    )


def _recover(recovery, pc, cmd, cfg, send, advance) -> NodeVisit:  # type: ignore[no-untyped-def]
    """Run the recovery node for at most ``cfg.recovery_time`` (a fault ends it)."""
    t_enter = pc.t
    pc.t_node = 0.0
    pc.goal[:] = math.nan
    if recovery.reset_setpoint:
        pc.hold_here()
    recovery.run.enter(pc)
    why = "recovered"
    try:
        while (
            pc.t_node < cfg.recovery_time
            and not recovery.error(pc)
            and not (pc.done and pc.t_node > 0)
        ):
            cmd.clear()
            recovery.run.command(pc, cmd)
            send()
            advance(-1)
    except (RobotFault, ControlError) as exc:
        why = f"{_fault_outcome(exc).value}: {exc}"
    return NodeVisit(recovery.name, t_enter, pc.t, why)
