"""A real Franka (FR3 / Panda) behind :class:`~teachfit.robot.interface.Robot`, over pylibfranka.

The driver runs libfranka's torque control in its own control thread: every tick it reads the
state (``readOnce``, which blocks until the robot's next 1 kHz packet), runs teachfit's
impedance law (fixed-gain or adaptive, from the ``ControllerSpec`` given at :meth:`reset`),
maps the TCP wrench to joint torques (:mod:`teachfit.robot.franka.tick`) and writes them
(``writeOnce``). pylibfranka 0.21 exposes this read/write interface rather than libfranka's
C++ callback, so this thread *is* the callback. The caller's thread never talks to the robot
during control: :meth:`command` posts a set-point that the loop adopts at its next tick,
:meth:`step` blocks on a condition until ``n`` more ticks have run and raises the fault the loop
latched.

Faults: libfranka's ``ControlException`` becomes :class:`ReflexFault` (a reflex) or
:class:`LimitViolation` (a limit), ``NetworkException`` :class:`ConnectionLost`; the driver's
own limits (:mod:`teachfit.robot.franka.safety`) raise :class:`LimitViolation`. After a fault
no torque is commanded: the loop ends with libfranka's motion-finished message (zero torques)
when the connection still stands, and every call but :meth:`reset`/:meth:`close` re-raises.
Ctrl-C (``KeyboardInterrupt``) during :meth:`step` holds the TCP where it is for
``stop_hold`` s, finishes the motion, and re-raises.

Why pylibfranka and not franky-control: teachfit's law must run in the 1 kHz torque loop with
teachfit's own Cartesian impedance; pylibfranka (Apache-2.0, Franka's own bindings) gives that
loop, the model (Jacobian, Coriolis) and the state with nothing in between. franky-control
(MIT) is built around its motion generators and its own impedance motions; it would add a
second controller stack to reason about and would not run our law per tick.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from teachfit.control import make_law
from teachfit.control.base import Controller
from teachfit.core.control import ControllerSpec, FixedGainSpec, ImpedanceLimits
from teachfit.core.errors import (
    ConnectionLost,
    LimitViolation,
    ReflexFault,
    RobotFault,
    TeachfitError,
)
from teachfit.core.geometry import Pose, wxyz_to_rotation
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.robot.franka.frames import FrankaFrames
from teachfit.robot.franka.safety import FrankaLimits
from teachfit.robot.franka.tick import TorqueTick

#: nominal apparent mass/inertia at the TCP (kg, kg·m²) for critical damping
FRANKA_APPARENT_MASS = (2.0, 2.0, 2.0, 0.05, 0.05, 0.05)


@dataclass(frozen=True)
class FrankaParams:
    """Driver settings.

    ``limits`` the safety limits, ``frames`` base/world and EE/TCP, ``apparent_mass`` (6,)
    (kg, kg·m²) for critical damping, ``reset_stiffness`` (N/m, N·m/rad) of the approach in
    :meth:`FrankaRobot.reset`, ``reset_tolerance`` (m, rad) it must reach, ``settle_timeout``
    (s) it may take after the set-point arrived, ``bias_ticks`` how many ticks the wrench bias
    averages, ``stop_hold`` (s) the hold before the loop ends on Ctrl-C, ``tick_timeout`` (s)
    without a tick after which :meth:`FrankaRobot.step` reports a lost connection.
    """

    limits: FrankaLimits = field(default_factory=FrankaLimits)
    frames: FrankaFrames = field(default_factory=FrankaFrames)
    apparent_mass: tuple[float, ...] = FRANKA_APPARENT_MASS
    reset_stiffness: tuple[float, ...] = (2000.0,) * 3 + (100.0,) * 3
    reset_tolerance: tuple[float, float] = (0.005, 0.05)
    settle_timeout: float = 3.0
    bias_ticks: int = 50
    stop_hold: float = 0.2
    tick_timeout: float = 1.5


def _fault_from(exc: BaseException) -> RobotFault:
    """The typed fault for a pylibfranka exception."""
    import pylibfranka as pf

    msg = f"{type(exc).__name__}: {exc}"
    if isinstance(exc, pf.NetworkException):
        return ConnectionLost(msg)
    text = str(exc).lower()
    if "reflex" in text:
        return ReflexFault(msg)
    if "violation" in text or "limit" in text:
        return LimitViolation(msg)
    return RobotFault(msg)


class FrankaRobot:
    """A Franka arm driven in torque control with teachfit's impedance law.

    Implements :class:`~teachfit.robot.interface.Robot`. Connecting starts the control loop
    holding the current pose (fixed-gain impedance); :meth:`reset` moves to a pose.

    Parameters
    ----------
    host : str
        Robot (or simulator) address.
    controller : ControllerSpec or None
        Law run after the first :meth:`reset` (default fixed-gain).
    params : FrankaParams or None
    realtime : bool
        Enforce libfranka's real-time scheduling check (a real robot needs an RT kernel; the
        simulator and tests pass ``False``).
    """

    name = "franka"
    wrench_source = "joint-torques"

    def __init__(
        self,
        host: str,
        controller: ControllerSpec | None = None,
        params: FrankaParams | None = None,
        realtime: bool = True,
    ) -> None:
        import pylibfranka as pf

        self._pf = pf
        self.host = host
        self.params = params or FrankaParams()
        self.controller_spec: ControllerSpec = controller or FixedGainSpec()
        rt = pf.RealtimeConfig.kEnforce if realtime else pf.RealtimeConfig.kIgnore
        self._realtime = rt
        try:
            self._robot = pf.Robot(host, rt)
            self._model = pf.Robot.load_model(self._robot)
        except (pf.NetworkException, RuntimeError) as exc:
            raise ConnectionLost(f"cannot connect to the Franka at {host}: {exc}") from exc
        self._tick = TorqueTick(self.params.frames, self.params.limits, self.control_period)
        self._mass = np.asarray(self.params.apparent_mass, dtype=float)
        self._cond = threading.Condition()
        self._lock = threading.Lock()
        self._pending_law: Controller | None = None
        self._pending_cmd: ImpedanceCommand | None = None
        self._ticks = 0
        self._t_abs = 0.0
        self._t0 = 0.0
        self._latest: RobotState | None = None
        self._fault: RobotFault | None = None
        self._finish = False
        self._thread: threading.Thread | None = None
        #: per-tick compute time (s) and time since the previous state (s), a ring buffer
        self.compute_times = np.zeros(20000)
        self.read_gaps = np.zeros(20000)
        self._law: Controller = make_law(FixedGainSpec(), self._mass, self.control_period)
        self._start_loop(hold_stiffness=self.params.reset_stiffness)

    # ------------------------------------------------------------------ Robot protocol
    @property
    def control_period(self) -> float:
        return 0.001

    @property
    def time(self) -> float:
        return self._t_abs - self._t0

    @property
    def ticks(self) -> int:
        """Control ticks run since the driver connected."""
        return self._ticks

    @property
    def joint_positions(self) -> np.ndarray:
        """The last measured joint angles (7,) (rad)."""
        return self._q_now.copy()

    def state(self) -> RobotState:
        if self._latest is None:
            raise ConnectionLost("no state received from the robot yet")
        return self._latest

    def command(self, cmd: ImpedanceCommand) -> None:
        """Post ``cmd`` to the control loop (adopted at its next tick) after the safety checks."""
        if self._fault is not None:
            raise self._fault
        self.params.limits.check_command(cmd)
        with self._lock:
            self._pending_cmd = cmd

    def step(self, n: int = 1) -> RobotState:
        """Wait until ``n`` more control ticks have run; raise the latched fault if any."""
        try:
            self._wait_ticks(n)
        except KeyboardInterrupt:
            self.stop()
            raise
        return self.state()

    def reset(self, pose: Pose, controller: ControllerSpec | None = None) -> RobotState:
        """Move the TCP to ``pose`` (world) at ``reset_speed``, wait until it settles, zero the
        wrench reading, and run ``controller`` (``None``: the current spec, state cleared).

        Clears a latched fault (libfranka's automatic error recovery, a new control loop).
        Raises :class:`LimitViolation` if ``pose`` is outside the workspace (nothing moves) or
        is not reached within the tolerance.
        """
        self.params.limits.check_target(pose.pos, "reset pose")
        if controller is not None:
            self.controller_spec = controller
        if self._fault is not None or self._thread is None or not self._thread.is_alive():
            self._restart()
        stiff = ImpedanceCommand(pos=pose.pos, stiffness=self.params.reset_stiffness).stiffness
        start = self.state().pose
        reset_law = make_law(FixedGainSpec(self._reset_limits()), self._mass, 0.001)
        self._install(reset_law, ImpedanceCommand.hold(start, stiffness=stiff, expires_after=1.0))
        for waypoint in _interpolate(start, pose, self.params.limits, 0.01):
            self.command(ImpedanceCommand.hold(waypoint, stiffness=stiff, expires_after=1.0))
            self.step(10)
        self._settle(pose)
        bias = np.zeros(6)
        for _ in range(self.params.bias_ticks):
            self.step(1)
            bias += self._latest.wrench + self._tick.bias  # type: ignore[union-attr]
        self._tick.bias = bias / self.params.bias_ticks
        self._tick.q_rest = self._q_now.copy()
        law = make_law(self.controller_spec, self._mass, self.control_period)
        self._install(law, ImpedanceCommand.hold(pose))
        self.step(1)
        self._t0 = self._t_abs
        return self.step(1)

    def close(self) -> None:
        """Finish the control loop (the arm holds where it is) and release the connection."""
        self._finish = True
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        self._thread = None
        robot, self._robot = getattr(self, "_robot", None), None
        if robot is not None:
            try:
                robot.stop()
            except Exception:  # noqa: BLE001 - best effort on a robot already gone
                pass

    def __enter__(self) -> FrankaRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ stopping
    def stop(self) -> None:
        """Hold the TCP where it is for ``stop_hold`` s, then finish the motion (Ctrl-C path)."""
        if self._fault is None and self._latest is not None:
            with self._lock:
                self._pending_cmd = ImpedanceCommand.hold(
                    self._latest.pose, stiffness=self.params.reset_stiffness
                )
            try:
                self._wait_ticks(int(self.params.stop_hold / self.control_period))
            except RobotFault:
                pass
        self._finish = True
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        if self._fault is None:
            self._fault = RobotFault("the control loop was stopped (Ctrl-C); reset() to go on")

    # ------------------------------------------------------------------ internals
    def _reset_limits(self) -> ImpedanceLimits:
        lim = self.params.limits
        return ImpedanceLimits(lim.max_force, lim.max_torque, lim.reset_speed, lim.reset_ang_speed)

    def _install(self, law: Controller, cmd: ImpedanceCommand) -> None:
        with self._lock:
            self._pending_law = law
            self._pending_cmd = cmd

    def _wait_ticks(self, n: int) -> None:
        with self._cond:
            target = self._ticks + n
            while self._ticks < target and self._fault is None:
                before = self._ticks
                if not self._cond.wait(timeout=self.params.tick_timeout) and self._ticks == before:
                    self._fault = ConnectionLost(
                        f"no control tick for {self.params.tick_timeout} s: the robot stopped "
                        "answering"
                    )
        if self._fault is not None:
            raise self._fault

    def _settle(self, pose: Pose) -> None:
        tol_p, tol_r = self.params.reset_tolerance
        for _ in range(int(self.params.settle_timeout / 0.01)):
            s = self.step(10)
            dp = float(np.linalg.norm(s.pos - pose.pos))
            dr = (wxyz_to_rotation(pose.quat).inv() * wxyz_to_rotation(s.quat)).magnitude()
            if dp < tol_p and dr < tol_r and np.linalg.norm(s.lin_vel) < 0.005:
                return
        raise LimitViolation(
            f"reset did not reach {np.round(pose.pos, 4).tolist()} within {tol_p} m / "
            f"{tol_r} rad (at {np.round(s.pos, 4).tolist()}, {dp:.4f} m, {dr:.3f} rad)"
        )

    def _restart(self) -> None:
        pf = self._pf
        if self._thread is not None:
            self._finish = True
            self._thread.join(timeout=2.0)
        if isinstance(self._fault, ConnectionLost) or self._robot is None:
            try:
                self._robot = pf.Robot(self.host, self._realtime)
                self._model = self._robot.load_model()
            except (pf.NetworkException, RuntimeError) as exc:
                raise ConnectionLost(f"cannot reconnect to {self.host}: {exc}") from exc
        else:
            try:
                self._robot.automatic_error_recovery()
            except Exception as exc:  # noqa: BLE001 - any failure here is a robot fault
                raise _fault_from(exc) from exc
        self._fault = None
        self._start_loop(hold_stiffness=self.params.reset_stiffness)

    def _start_loop(self, hold_stiffness: Any) -> None:
        pf = self._pf
        try:
            first = self._robot.read_once()
        except Exception as exc:  # noqa: BLE001
            raise _fault_from(exc) from exc
        self._q_now = np.asarray(first.q, dtype=float)
        self.robot_mode = str(first.robot_mode).split(".")[-1]
        self._tick.kinematics(first, self._model)
        self._tick.q_rest = self._q_now.copy()
        self._tick.tau_prev = np.zeros(7)
        here = Pose(self._tick.pos, self._tick.quat.copy())
        self._law = make_law(FixedGainSpec(self._reset_limits()), self._mass, 0.001)
        self._law.set_command(
            ImpedanceCommand.hold(here, stiffness=hold_stiffness, expires_after=1.0), self._t_abs
        )
        self._latest = self._tick.robot_state(self.time, first)
        self._finish = False
        try:
            control = self._robot.start_torque_control()
        except Exception as exc:  # noqa: BLE001
            raise _fault_from(exc) from exc
        self._thread = threading.Thread(
            target=self._loop, args=(control, pf), name="franka-control", daemon=True
        )
        self._thread.start()

    def _loop(self, control: Any, pf: Any) -> None:
        """The control thread: one iteration per 1 kHz robot packet."""
        import time as _time

        tick, model, limits = self._tick, self._model, self.params.limits
        buf_c, buf_g, size = self.compute_times, self.read_gaps, len(self.compute_times)
        try:
            while True:
                state, gap = control.readOnce()
                start = _time.perf_counter()
                self._t_abs += self.control_period
                self._q_now = np.asarray(state.q, dtype=float)
                tick.kinematics(state, model)
                if self._pending_law is not None or self._pending_cmd is not None:
                    with self._lock:
                        if self._pending_law is not None:
                            self._law, self._pending_law = self._pending_law, None
                        if self._pending_cmd is not None:
                            self._law.set_command(self._pending_cmd, self._t_abs)
                            self._pending_cmd = None
                why = limits.check_motion(tick.pos, tick.lin_vel, tick.ang_vel)
                if why or self._finish:
                    if why:
                        self._fault = LimitViolation(why)
                    self._publish(state)
                    self._send_finish(control, pf)
                    return
                tau = tick.torques(self._t_abs, self._law, state, model)
                i = self._ticks % size
                buf_g[i] = gap.to_sec()
                self._publish(state)
                buf_c[i] = _time.perf_counter() - start
                control.writeOnce(pf.Torques(tau.tolist()))
        except BaseException as exc:  # noqa: BLE001 - every loop failure is latched as a fault
            fault = exc if isinstance(exc, RobotFault) else _fault_from(exc)
            if not isinstance(exc, (pf.NetworkException, pf.ControlException)):
                if not isinstance(exc, TeachfitError):
                    fault = RobotFault(f"control loop failed: {type(exc).__name__}: {exc}")
            with self._cond:
                self._fault = fault
                self._cond.notify_all()

    def _publish(self, state: Any) -> None:
        latest = self._tick.robot_state(self.time, state)
        with self._cond:
            self._latest = latest
            self._ticks += 1
            self._cond.notify_all()

    def _send_finish(self, control: Any, pf: Any) -> None:
        done = pf.Torques([0.0] * 7)
        done.motion_finished = True
        try:
            control.writeOnce(done)
        except Exception:  # noqa: BLE001 - the connection may already be gone
            pass
        with self._cond:
            self._cond.notify_all()


def _interpolate(start: Pose, goal: Pose, limits: FrankaLimits, dt: float) -> list[Pose]:
    """Poses from ``start`` to ``goal`` every ``dt`` s at the reset speeds (goal included)."""
    from scipy.spatial.transform import Slerp

    from teachfit.core.geometry import rotation_to_wxyz

    dist = float(np.linalg.norm(goal.pos - start.pos))
    r0, r1 = wxyz_to_rotation(start.quat), wxyz_to_rotation(goal.quat)
    angle = float((r0.inv() * r1).magnitude())
    duration = max(dist / limits.reset_speed, angle / limits.reset_ang_speed, dt)
    n = int(np.ceil(duration / dt))
    s = np.linspace(0.0, 1.0, n + 1)[1:]
    s = 0.5 - 0.5 * np.cos(np.pi * s)  # smooth start and stop
    from scipy.spatial.transform import Rotation

    rots = Slerp([0.0, 1.0], Rotation.concatenate([r0, r1]))(s)
    quats = rotation_to_wxyz(rots)
    return [
        Pose(start.pos + si * (goal.pos - start.pos), qi) for si, qi in zip(s, quats, strict=True)
    ]
