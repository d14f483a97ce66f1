"""The Franka driver's control thread: pylibfranka's 1 kHz read/write torque loop.

pylibfranka 0.21 exposes libfranka's active-control interface (``start_torque_control`` ->
``readOnce`` / ``writeOnce``) rather than the C++ callback, so this thread *is* the callback:
``readOnce`` blocks until the robot's next state packet, the tick computes torques
(:class:`~teachfit.robot.franka.tick.TorqueTick`) and ``writeOnce`` sends them; then, while the
robot works on its next packet, the tick's state is published. Other threads never talk to the
robot during control: they post a command (adopted at the next tick), install a new law, wait
for ticks on a condition (woken at the tick they wait for), and read the latched fault.

After a fault no torque is commanded: when the driver's own limit trips (or a finish is asked)
the loop sends libfranka's motion-finished message with zero torques and ends; a libfranka
exception (reflex, limit, network) ends it at once.
"""

from __future__ import annotations

import threading
import time
from typing import Any

import numpy as np

from teachfit.control.base import Controller
from teachfit.core.errors import (
    ConnectionLost,
    LimitViolation,
    ReflexFault,
    RobotFault,
)
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.robot.franka.priority import ThreadClass, to_fifo
from teachfit.robot.franka.safety import FrankaLimits
from teachfit.robot.franka.tick import TorqueTick


def fault_from(exc: BaseException, robot: str = "the robot") -> RobotFault:
    """The typed fault for a pylibfranka exception (or any other loop failure); ``robot``
    names the robot in a lost connection's message (``"the Franka at 192.168.1.2"``)."""
    import pylibfranka as pf

    if isinstance(exc, RobotFault):
        return exc
    msg = f"{type(exc).__name__}: {exc}"
    if isinstance(exc, pf.NetworkException):
        return ConnectionLost(
            f"lost the connection to {robot} ({msg}): check that it is on and reachable "
            "(the simulator still running), then run again"
        )
    if isinstance(exc, (pf.ControlException, pf.CommandException)):
        text = str(exc).lower()
        if "reflex" in text:
            return ReflexFault(msg)
        if "violation" in text or "limit" in text:
            return LimitViolation(msg)
        return RobotFault(msg)
    return RobotFault(f"control loop failed: {msg}")


class ControlLoop:
    """One torque-control session's thread, mailbox, tick counter and latched fault.

    Parameters
    ----------
    tick : TorqueTick
    limits : FrankaLimits
    period : float
        Control period (s).
    buffer : int
        Ticks of timing kept (ring buffers ``compute_times`` and ``read_gaps``, s).
    robot : str
        The robot, as faults name it (``"the Franka at 192.168.1.2"``).

    The thread puts itself in ``SCHED_FIFO`` before its first tick where the process may
    (:mod:`.priority`, as libfranka's own control loop does); :attr:`thread_class` says what it
    got.
    """

    def __init__(
        self,
        tick: TorqueTick,
        limits: FrankaLimits,
        period: float,
        buffer: int = 120_000,
        robot: str = "the robot",
    ) -> None:
        self.robot = robot
        #: the control thread's scheduling class (set when its thread starts)
        self.thread_class = ThreadClass("SCHED_OTHER", why="the loop has not started")
        self.tick = tick
        self.limits = limits
        self.period = period
        self.cond = threading.Condition()
        self._lock = threading.Lock()
        self._pending_law: Controller | None = None
        self._pending_cmd: ImpedanceCommand | None = None
        self._pending_clock = False
        self.law: Controller | None = None
        self.ticks = 0
        self.t_abs = 0.0
        self.t0 = 0.0
        self.latest: RobotState | None = None
        #: the last tick's pylibfranka ``RobotState`` (what the model's functions take)
        self.raw: Any = None
        self.fault: RobotFault | None = None
        #: the tick count the earliest waiter waits for: the control thread wakes waiters then,
        #: not every tick (a waiter woken every tick would take the GIL from it 1000 times a s)
        self._wake_at = np.inf
        self.q = np.zeros(7)
        self._finish = False
        self._thread: threading.Thread | None = None
        self._tap_every = 0
        self._tapped: list[RobotState] = []
        #: per-tick compute time (s, state read -> torques ready to send) and gap since the
        #: previous state (s)
        self.compute_times = np.zeros(buffer)
        self.read_gaps = np.zeros(buffer)

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def start(self, robot: Any, model: Any, first: Any, law: Controller) -> None:
        """Start torque control on ``robot`` with ``law`` (already commanded); ``first`` is a
        state read just before (``read_once``)."""
        import pylibfranka as pf

        self.q = np.asarray(first.q, dtype=float)
        self.tick.kinematics(first, model)
        self.tick.tau_prev = np.zeros(7)
        self.law = law
        self.latest = self.tick.robot_state(self.t_abs - self.t0)
        self.raw = first
        self.fault = None
        self._finish = False
        try:
            control = robot.start_torque_control()
        except Exception as exc:  # noqa: BLE001 - any refusal is a robot fault
            raise fault_from(exc, self.robot) from exc
        self._thread = threading.Thread(
            target=self._run, args=(control, model, pf), name="franka-control", daemon=True
        )
        self._thread.start()

    def post(self, cmd: ImpedanceCommand) -> None:
        """Adopt ``cmd`` at the next tick."""
        with self._lock:
            self._pending_cmd = cmd

    def install(self, law: Controller, cmd: ImpedanceCommand, restart_clock: bool = False) -> None:
        """Run ``law`` with ``cmd`` from the next tick on; ``restart_clock``: that tick also
        reads ``t = period`` (the clock is restarted in the control thread, on the tick that
        adopts the law, so no state published in between can read a stale or zero time)."""
        with self._lock:
            self._pending_law = law
            self._pending_cmd = cmd
            self._pending_clock = restart_clock

    def wait(self, n: int, timeout: float) -> None:
        """Block until ``n`` more ticks ran; raise the latched fault, or :class:`ConnectionLost`
        when no tick came for ``timeout`` s."""
        with self.cond:
            target = self.ticks + n
            while self.ticks < target and self.fault is None:
                before = self.ticks
                self._wake_at = min(self._wake_at, target)
                if not self.cond.wait(timeout=timeout) and self.ticks == before:
                    self.fault = ConnectionLost(
                        f"no control tick for {timeout} s: {self.robot} stopped answering"
                    )
        if self.fault is not None:
            raise self.fault

    def tap(self, every: int) -> None:
        """Keep the state of every ``every``-th tick, sampled in the control thread."""
        with self.cond:
            self._tapped = []
            self._tap_every = int(every)

    def untap(self) -> list[RobotState]:
        """Stop sampling; the states kept since :meth:`tap`."""
        with self.cond:
            self._tap_every, out, self._tapped = 0, self._tapped, []
        return out

    def finish(self, timeout: float = 2.0) -> None:
        """End the loop (motion finished) and join the thread."""
        self._finish = True
        if self._thread is not None:
            self._thread.join(timeout=timeout)
        self._thread = None

    # ------------------------------------------------------------------ the thread
    def _run(self, control: Any, model: Any, pf: Any) -> None:
        self.thread_class = to_fifo()
        tick, period = self.tick, self.period
        buf_c, buf_g, size = self.compute_times, self.read_gaps, len(self.compute_times)
        try:
            while True:
                state, gap = control.readOnce()
                start = time.perf_counter()
                self.t_abs += period
                if self._pending_law is not None or self._pending_cmd is not None:
                    self._adopt()
                if self._finish:
                    tick.kinematics(state, model)
                    why = ""
                else:
                    why = tick.step(self.t_abs, self.law, state, model)  # type: ignore[arg-type]
                if why or self._finish:
                    if why:
                        self.fault = LimitViolation(why)
                    self._publish(state)
                    self._send_finish(control, pf)
                    return
                torques = pf.Torques(tick.tau.tolist())
                i = self.ticks % size
                buf_c[i] = time.perf_counter() - start
                control.writeOnce(torques)
                buf_g[i] = gap.to_sec()
                self._publish(state)  # for the other threads, after the torques went out
        except BaseException as exc:  # noqa: BLE001 - every loop failure is latched as a fault
            with self.cond:
                self.fault = fault_from(exc, self.robot)
                self.cond.notify_all()

    def _adopt(self) -> None:
        with self._lock:
            if self._pending_law is not None:
                self.law, self._pending_law = self._pending_law, None
            if self._pending_clock:
                self.t0, self._pending_clock = self.t_abs - self.period, False
            if self._pending_cmd is not None:
                self.tick.command(self.law, self._pending_cmd, self.t_abs)  # type: ignore[arg-type]
                self._pending_cmd = None

    def _publish(self, state: Any) -> None:
        latest = self.tick.robot_state(self.t_abs - self.t0)
        q = self.tick.q.copy()
        with self.cond:
            self.q = q
            self.latest = latest
            self.raw = state  # libfranka's state of this tick (for the model's mass)
            self.ticks += 1
            if self._tap_every and self.ticks % self._tap_every == 0:
                self._tapped.append(latest)
            if self.ticks >= self._wake_at:
                self._wake_at = np.inf
                self.cond.notify_all()

    def _send_finish(self, control: Any, pf: Any) -> None:
        done = pf.Torques([0.0] * 7)
        done.motion_finished = True
        try:
            control.writeOnce(done)
        except Exception:  # noqa: BLE001 - the connection may already be gone
            pass
        with self.cond:
            self.cond.notify_all()
