"""Run a skill on a :class:`~teachfit.robot.interface.Robot` and trace what happened.

Every command period ``dt`` (``command_rate``; the robot's controller runs in between at its
own rate) the executor

1. updates the :class:`~teachfit.skills.percept.Percept` from the measured state;
2. checks, in this order, the skill's success condition (stop, positive), the global and the
   active node's error conditions (stop, negative, run the recovery node), then the active
   node's transitions (first that holds wins; the target is entered at once);
3. asks the active primitive for a twist, feed-forward wrench and stiffness (task frame),
   sends the set-point ``(p_d, q_d)`` with them to the robot (world frame) and integrates it,
   ``p_d += v dt``, ``q_d = exp(w dt) q_d``.

The trace lists the nodes visited with entry / exit times (s since the skill started) and
the reason each was left, the first-contact time (the measured force first reaching
``contact_force``), and a log of pose, wrench and active node at ``log_rate``. A diverging
simulation ends the execution as failed (``outcome = "diverged"``); it never raises.
Buffers are allocated once per execution; the loop allocates only the command object.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import mujoco
import numpy as np

from teachfit.core.errors import ControlError, SimulationDiverged, SkillError
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.interface import Robot
from teachfit.skills.conditions import Any_, Condition
from teachfit.skills.graph import Skill
from teachfit.skills.percept import MPCommand, Percept
from teachfit.tasks.base import Task


@dataclass(frozen=True)
class ExecConfig:
    """Execution settings: ``command_rate`` and ``log_rate`` (Hz); ``contact_force`` (N)
    marks first contact; ``max_time`` (s) is a hard cap besides the skill's own error
    condition; ``recovery_time`` (s) bounds the recovery node (0: skip recovery)."""

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
    """One stay in a node: ``t_enter``, ``t_exit`` (s since the skill started), why it ended."""

    node: str
    t_enter: float
    t_exit: float
    reason: str


@dataclass(frozen=True)
class ExecutionLog:
    """Signals at ``log_rate``: ``t`` (T,) s, ``pos`` (T, 3) m, ``quat`` (T, 4), ``wrench``
    (T, 6) N, N·m (world frame, TCP), ``depth`` (T,) m below the task frame's x-y plane,
    ``node`` (T,) index into :attr:`ExecutionTrace.node_names` (-1: recovery)."""

    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    wrench: np.ndarray
    depth: np.ndarray
    node: np.ndarray


@dataclass(frozen=True)
class ExecutionTrace:
    """What one execution did.

    ``outcome``: ``"success"``, ``"error"`` (an error condition fired), ``"precondition"``
    (the skill could not start), ``"diverged"`` or ``"max-time"``. ``t_end`` (s) is when the
    outcome was decided (before recovery); ``remaining`` (m) the TCP's distance to ``goal``
    then (at the last finite state if the simulation diverged); ``inserted`` the task's
    ground-truth success test then (``None`` without a task).
    """

    skill: str
    outcome: str
    reason: str
    visits: tuple[NodeVisit, ...]
    t_first_contact: float
    t_end: float
    remaining: float
    inserted: bool | None
    log: ExecutionLog
    node_names: tuple[str, ...]
    steps: int
    wall_s: float

    @property
    def success(self) -> bool:
        """The success condition fired (and, with a task, the part is truly inserted)."""
        return self.outcome == "success" and self.inserted is not False


class _Log:
    def __init__(self, n: int) -> None:
        self.t, self.pos, self.quat = np.zeros(n), np.zeros((n, 3)), np.zeros((n, 4))
        self.wrench, self.depth = np.zeros((n, 6)), np.zeros(n)
        self.node = np.zeros(n, dtype=int)
        self.k = 0

    def add(self, pc: Percept, wrench: np.ndarray, node: int) -> None:
        k = self.k
        if k < self.t.size:
            self.t[k], self.depth[k], self.node[k] = pc.t, -pc.p[2], node
            self.pos[k], self.quat[k], self.wrench[k] = pc.pos, pc.quat, wrench
            self.k = k + 1

    def freeze(self) -> ExecutionLog:
        k = self.k
        return ExecutionLog(
            self.t[:k].copy(),
            self.pos[:k].copy(),
            self.quat[:k].copy(),
            self.wrench[:k].copy(),
            self.depth[:k].copy(),
            self.node[:k].copy(),
        )


def _holding(cond: Condition, values: dict[str, float], pc: Percept) -> str:
    """The parts of an (``any``-)condition that hold now, described (for the trace)."""
    parts = cond.parts if isinstance(cond, Any_) else (cond,)
    held = [c.describe() for c in parts if c.compile(values)(pc)]
    return " ∨ ".join(held) if held else cond.describe()


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
) -> ExecutionTrace:
    """Reset ``robot`` at ``start`` and run ``skill`` with ``learned`` values (defaults for
    missing names) in the task frame ``task2world``; see the module docstring.

    ``goal2world`` is where the TCP should end (default: the task frame's origin) for the
    remaining distance; ``task`` gives the ground-truth insertion test. Invalid parameter
    values raise :class:`SkillError` before the robot moves.
    """
    cfg = config or ExecConfig()
    nodes, recovery, success, error, pre = skill.compile(learned)
    names = tuple(n.name for n in nodes)
    period = robot.control_period
    ticks = max(1, round(1.0 / (cfg.command_rate * period)))
    dt = ticks * period
    log_every = max(1, round(1.0 / (cfg.log_rate * dt)))
    pc = Percept(task2world, dt)
    goal = goal2world.pos if goal2world is not None else task2world.pos
    log = _Log(int(math.ceil((cfg.max_time + cfg.recovery_time) / (dt * log_every))) + 4)
    cmd = MPCommand()
    rot = pc.rot
    k_w = np.zeros((6, 6))
    dq, qtmp = np.zeros(4), np.zeros(4)
    last_pos = np.zeros(3)  # the last finite TCP position (world)
    wall0 = time.perf_counter()

    state = robot.reset(start)
    t0 = state.t
    pc.update(state, 0.0)
    pc.hold_here()
    last_pos[:] = pc.pos
    visits: list[NodeVisit] = []
    t_contact = math.nan
    steps = 0
    idx = names.index(skill.start)
    active = nodes[idx]
    t_enter = 0.0
    outcome, reason = "max-time", f"hard cap of {cfg.max_time:g} s"
    if pre is not None and not pre(pc):
        outcome, reason = "precondition", "precondition does not hold"
    else:
        active.run.enter(pc)

    def send() -> None:
        """Command the set-point for the coming period and integrate it (task -> world)."""
        v, w = cmd.twist[:3], cmd.twist[3:]
        pos_w, quat_w = pc.to_world_pose(pc.p_d, pc.q_d)
        k = cmd.stiffness
        k_w[:3, :3] = (rot * k[:3]) @ rot.T
        k_w[3:, 3:] = (rot * k[3:]) @ rot.T
        robot.command(
            ImpedanceCommand(
                pos=pos_w,
                quat=quat_w,
                lin_vel=rot @ v,
                ang_vel=rot @ w,
                wrench_ff=np.concatenate([rot @ cmd.wrench[:3], rot @ cmd.wrench[3:]]),
                stiffness=k_w,
            )
        )
        pc.p_d += v * dt
        ang = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) * dt
        if ang > 0.0:
            s = math.sin(ang / 2) / (ang / dt)
            dq[:] = (math.cos(ang / 2), w[0] * s, w[1] * s, w[2] * s)
            mujoco.mju_mulQuat(qtmp, dq, pc.q_d)
            pc.q_d[:] = qtmp / math.sqrt(float(qtmp @ qtmp))

    def advance(node_index: int) -> None:
        """Step the robot one command period and update the percept (may raise)."""
        nonlocal steps, t_contact
        st = robot.step(ticks)
        steps += ticks
        t = st.t - t0
        pc.update(st, t)
        pc.t_node = t - t_enter
        if not (np.all(np.isfinite(pc.p)) and np.all(np.isfinite(pc.f))):
            raise SimulationDiverged(f"non-finite state at t={t:.3f} s")
        last_pos[:] = pc.pos
        if math.isnan(t_contact) and math.hypot(*st.wrench[:3]) >= cfg.contact_force:
            t_contact = t
        if (steps // ticks) % log_every == 0:
            log.add(pc, st.wrench, node_index)

    log.add(pc, state.wrench, idx)
    diverged = False
    while outcome == "max-time":
        if success(pc):
            outcome, reason = "success", "success condition"
            break
        if error(pc) or active.error(pc):
            outcome = "error"
            glob = error(pc)
            cond = skill.error if glob else skill.node(active.name).error
            which = _holding(cond, skill.resolve(learned), pc)  # type: ignore[arg-type]
            reason = f"{'skill' if glob else active.name} error: {which}"
            break
        for check, target, desc in active.transitions:
            if check(pc):
                visits.append(NodeVisit(active.name, t_enter, pc.t, f"-> {names[target]}: {desc}"))
                idx, active, t_enter = target, nodes[target], pc.t
                pc.t_node = 0.0
                pc.goal[:] = math.nan
                if active.reset_setpoint:
                    pc.hold_here()
                active.run.enter(pc)
                break
        if pc.t >= cfg.max_time:
            break
        cmd.clear()
        active.run.command(pc, cmd)
        try:
            send()
            advance(idx)
        except (SimulationDiverged, ControlError) as exc:
            outcome, reason, diverged = "diverged", f"diverged: {exc}", True
    t_end = pc.t
    if outcome != "precondition":
        visits.append(NodeVisit(active.name, t_enter, t_end, reason))
    remaining = float(np.linalg.norm(last_pos - goal))
    inserted = None if task is None or diverged else bool(task.ground_truth_inserted(Pose(pc.pos, pc.quat)))
    if outcome == "error" and recovery is not None and cfg.recovery_time > 0:
        t_enter = pc.t
        pc.t_node = 0.0
        pc.goal[:] = math.nan
        if recovery.reset_setpoint:
            pc.hold_here()
        recovery.run.enter(pc)
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
            why = "recovered"
        except (SimulationDiverged, ControlError) as exc:
            why = f"diverged: {exc}"
        visits.append(NodeVisit(recovery.name, t_enter, pc.t, why))
    return ExecutionTrace(
        skill=skill.name,
        outcome=outcome,
        reason=reason,
        visits=tuple(visits),
        t_first_contact=t_contact,
        t_end=t_end,
        remaining=remaining,
        inserted=inserted,
        log=log.freeze(),
        node_names=names,
        steps=steps,
        wall_s=time.perf_counter() - wall0,
    )
