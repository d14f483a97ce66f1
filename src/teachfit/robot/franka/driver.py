"""A real Franka (FR3 / Panda) behind :class:`~teachfit.robot.interface.Robot`, over pylibfranka.

The driver runs libfranka's torque control in its own control thread
(:mod:`teachfit.robot.franka.loop`): every tick it reads the state, runs teachfit's impedance
law (fixed-gain or adaptive, from the ``ControllerSpec`` given at :meth:`reset`), maps the TCP
wrench to joint torques (:mod:`teachfit.robot.franka.tick`) and writes them. :meth:`command`
posts a set-point (after the safety checks) that the loop adopts at its next tick;
:meth:`step` blocks on a condition until ``n`` more ticks ran and raises the latched fault.

Faults: libfranka's ``ControlException`` becomes :class:`ReflexFault` (a reflex) or
:class:`LimitViolation` (a limit), ``NetworkException`` :class:`ConnectionLost` (so does a loop
that stops ticking); the driver's own limits (:mod:`teachfit.robot.franka.safety`) raise
:class:`LimitViolation`. After a fault no torque is commanded and every call but
:meth:`reset` / :meth:`close` re-raises it. Ctrl-C (``KeyboardInterrupt``; SIGTERM's
``SystemExit`` in the CLI) during :meth:`step` holds the TCP where it is for ``stop_hold`` s,
finishes the motion, and re-raises. Connecting is bounded by ``connect_timeout`` and can be
interrupted (:mod:`teachfit.robot.franka.connect`).

Why pylibfranka and not franky-control: teachfit's law must run in the 1 kHz torque loop;
pylibfranka (Apache-2.0, Franka's own bindings) gives that loop, the model (Jacobian,
Coriolis) and the state with nothing in between. franky-control (MIT) is built around its own
motion generators and impedance motions: a second controller stack, and no way to run our law
per tick. Its motion-level parts (joint motions for reset) are not needed: reset is a slow
Cartesian impedance approach with our own law.
"""

from __future__ import annotations

import gc
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from teachfit.control import make_law
from teachfit.control.base import Controller
from teachfit.core.control import AdaptiveSpec, ControllerSpec, FixedGainSpec, ImpedanceLimits
from teachfit.core.errors import ConnectionLost, ControlError, LimitViolation, RobotFault
from teachfit.core.geometry import Pose, wxyz_to_rotation
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.core.teaching import NO_TEACHER_HINTS, TeacherHints
from teachfit.robot.franka import priority
from teachfit.robot.franka.connect import CONNECT_TIMEOUT, probe
from teachfit.robot.franka.frames import FrankaFrames, approach_waypoints, col_major
from teachfit.robot.franka.grasp import GraspWatch, connect_gripper
from teachfit.robot.franka.load import PartLoad
from teachfit.robot.franka.loop import ControlLoop, fault_from
from teachfit.robot.franka.priority import ThreadClass
from teachfit.robot.franka.reflex import ReflexThresholds, check_reflex_force, reflex_thresholds
from teachfit.robot.franka.reset_path import (
    ResetCell,
    ResetGuard,
    brake_decel,
    brake_time,
    leave_stiffness,
    release_command,
    reset_via_points,
)
from teachfit.robot.franka.safety import FrankaLimits
from teachfit.robot.franka.tick import (
    ROTOR_INERTIA,
    TorqueTick,
    operational_inertia,
    operational_mass,
)

if TYPE_CHECKING:
    from teachfit.tasks.base import Task

#: GIL switch interval (s) while a driver runs
SWITCH_INTERVAL = 2e-4


#: the least apparent mass/inertia (kg, kg·m²) the law's damping assumes: libfranka's mass
#: matrix leaves the motors' rotor inertia out, so about the tool axis it reads 0.002 kg·m²
#: where the twin's cell (with the joints' armature) has 0.075
MIN_APPARENT_MASS = (2.0, 2.0, 2.0, 0.05, 0.05, 0.05)


@dataclass(frozen=True)
class FrankaParams:
    """Driver settings.

    ``limits`` the safety limits, ``frames`` base/world and EE/TCP, ``apparent_mass`` (6,) (kg,
    kg·m²) for the law's critical damping (``None``: the diagonal of the operational-space
    inertia at the TCP from libfranka's mass matrix, at connect and at each reset's goal, as the
    fr3 robot takes it; a constant 2 kg / 0.05 kg·m² under-damped the FR3, whose TCP weighs 5-15
    kg and 0.08-1.2 kg·m² over the cell; at least :data:`MIN_APPARENT_MASS`),
    ``reset_stiffness`` (N/m, N·m/rad) of the approach in :meth:`FrankaRobot.reset`,
    ``reset_tolerance`` (m, rad) it must reach, ``settle_timeout`` (s of robot time) it may take
    after the set-point arrived, ``bias_ticks`` how many ticks the wrench bias averages,
    ``stop_hold`` (s) the hold before the loop ends on Ctrl-C, ``tick_timeout`` (s) without a
    tick after which the connection counts as lost, ``connect_timeout`` (s, wall clock) a
    connect may take before the robot counts as not answering
    (:mod:`teachfit.robot.franka.connect`), ``reset_cell`` the hole a reset leaves along its
    axis first (:mod:`teachfit.robot.franka.reset_path`; ``None``: straight lines),
    ``reflex_force`` (N) the firmware's collision reflex force threshold set on connect
    (:mod:`teachfit.robot.franka.reflex`; ``None``: 1.25 x ``limits.max_force``, 75 N),
    ``load`` the held part, sent as the firmware's load (``setLoad``) on connect and after each
    recovery so its gravity model carries it (:mod:`teachfit.robot.franka.load`; ``None``:
    none sent, the firmware keeps the load it has).
    """

    limits: FrankaLimits = field(default_factory=FrankaLimits)
    frames: FrankaFrames = field(default_factory=FrankaFrames)
    apparent_mass: tuple[float, ...] | None = None
    reset_stiffness: tuple[float, ...] = (2000.0,) * 3 + (100.0,) * 3
    reset_tolerance: tuple[float, float] = (0.005, 0.05)
    settle_timeout: float = 3.0
    bias_ticks: int = 50
    stop_hold: float = 0.2
    tick_timeout: float = 1.5
    connect_timeout: float = CONNECT_TIMEOUT
    reset_cell: ResetCell | None = None
    reflex_force: float | None = None
    load: PartLoad | None = None

    def __post_init__(self) -> None:
        if self.reflex_force is not None:
            check_reflex_force(self.reflex_force)


class FrankaRobot:
    """A Franka arm driven in torque control with teachfit's impedance law.

    Implements :class:`~teachfit.robot.interface.Robot`. Connecting starts the control loop
    holding the current pose; :meth:`reset` moves to a pose.

    Parameters
    ----------
    host : str
        Robot (or simulator) address.
    controller : ControllerSpec or None
        Law run after the first :meth:`reset` (default fixed-gain).
    params : FrankaParams or None
    realtime : bool
        Enforce real time as libfranka's own control loop does: its check for a real-time
        kernel, and the control thread in ``SCHED_FIFO`` at the highest priority
        (:mod:`.priority`; :class:`RobotFault` when the process may not use it). A real robot
        needs both; the simulator, the twin and the tests pass ``False``, where the control
        thread still takes ``SCHED_FIFO`` if the process may (libfranka's behaviour), as does
        the caller's thread (pylibfranka's, :mod:`.priority`) until :meth:`close`.
    confirm : callable or None
        Called with each reset's goal before the arm moves (:mod:`.confirm`); raising stops.
    """

    name = "franka"
    wrench_source = "joint-torques"

    def __init__(
        self,
        host: str,
        controller: ControllerSpec | None = None,
        params: FrankaParams | None = None,
        realtime: bool = True,
        confirm: Callable[[Pose], None] | None = None,
    ) -> None:
        import pylibfranka as pf

        #: asked before each reset with its goal (``--confirm``); raises to stop
        self.confirm = confirm
        #: the hand's grasp, checked at each reset (None: no hand answers, ``grasp_note`` why)
        self.grasp: GraspWatch | None = None
        self.grasp_note = ""
        self._pf = pf
        self.host = host
        self.params = params or FrankaParams()
        self.controller_spec: ControllerSpec = controller or FixedGainSpec()
        self._realtime = pf.RealtimeConfig.kEnforce if realtime else pf.RealtimeConfig.kIgnore
        if realtime:
            allowed = priority.probe()
            if not allowed.realtime:
                raise RobotFault(
                    f"the control thread may not run in SCHED_FIFO ({allowed.why}); "
                    "or pass --no-realtime (a simulator or the twin)"
                )
        self._robot: Any = None  # a pylibfranka.Robot (untyped) once connected
        #: the caller's scheduling class before pylibfranka raised it, restored by close()
        self._caller_class = priority.current()
        self._connect()
        self.grasp, self.grasp_note = connect_gripper(pf, host)
        # A garbage collection runs in whichever thread allocates and holds the GIL throughout,
        # so the control thread waits for it: a full one over everything a study process holds
        # (its imports, the scene, the learner) stopped the loop for 105-128 ms against the
        # twin, and a real arm stops itself after 20 ms without a command (communication
        # constraints). What exists now lives as long as the connection: out of the
        # collector's generations, the full collections scan what came since (a 22-27 ms
        # stall in the same runs). Undone by close().
        gc.freeze()
        # the control thread must get the GIL within a fraction of a tick when the caller's
        # thread runs Python: Python's default switch interval (5 ms) would let a busy caller
        # delay a tick by up to 5 periods. Process-wide; restored by close().
        self._switch_interval = sys.getswitchinterval()
        sys.setswitchinterval(min(self._switch_interval, SWITCH_INTERVAL))
        fixed = self.params.apparent_mass
        self._mass = np.ones(6) if fixed is None else np.asarray(fixed, dtype=float)
        tick = TorqueTick(self.params.frames, self.params.limits, self.control_period)
        where = f"the Franka at {host}"
        self._loop = ControlLoop(tick, self.params.limits, self.control_period, robot=where)
        #: completed resets (a reset restarts the clock)
        self.resets = 0
        #: where :meth:`finish_execution` let go (start pose, way-out stiffness) until a command
        self._let_go_at: tuple[Pose, np.ndarray] | None = None
        cell = self.params.reset_cell
        #: lateral force watch while a reset leaves the hole; its ``peaks`` (N), one per reset
        self.reset_guard = ResetGuard(cell) if cell is not None else None
        self.robot_mode = "unknown"
        #: the collision thresholds sent to the firmware (set on connect and each restart)
        self.reflex: ReflexThresholds | None = None
        try:
            self._start()
        except BaseException:
            self.close()
            raise

    # ------------------------------------------------------------------ Robot protocol
    @property
    def control_period(self) -> float:
        return 0.001

    @property
    def time(self) -> float:
        return self._loop.t_abs - self._loop.t0

    def state(self) -> RobotState:
        if self._loop.latest is None:
            raise ConnectionLost("no state received from the robot yet")
        return self._loop.latest

    def command(self, cmd: ImpedanceCommand) -> None:
        """Post ``cmd`` to the control loop (adopted at its next tick) after the safety checks;
        a command over a limit raises :class:`LimitViolation` and is not sent."""
        if self._loop.fault is not None:
            raise self._loop.fault
        self.params.limits.check_command(cmd)
        self._let_go_at = None  # the arm commanded on: a reset lets go where it is then
        spec = self.controller_spec
        if isinstance(spec, AdaptiveSpec):  # what the law's set_command would refuse in-loop
            diag = np.diag(cmd.stiffness)
            if np.any(diag > np.asarray(spec.limits.k_max)):
                raise ControlError(f"command stiffness {diag.tolist()} exceeds k_max")
        self._loop.post(cmd)

    def step(self, n: int = 1) -> RobotState:
        """Wait until ``n`` more control ticks have run; raise the latched fault if any."""
        try:
            self._loop.wait(n, self.params.tick_timeout)
        except (KeyboardInterrupt, SystemExit):  # Ctrl-C, or SIGTERM (teachfit's CLI)
            self.stop()
            raise
        return self.state()

    def reset(self, pose: Pose, controller: ControllerSpec | None = None) -> RobotState:
        """Move the TCP to ``pose`` (world) at the reset speeds, wait until it settles, zero the
        wrench reading, and run ``controller`` (``None``: the current spec, state cleared).

        The skill's control ends first, if :meth:`finish_execution` did not end it (a part in
        the hole braked and held at rest there: :meth:`_let_go`), then the grasp is checked and
        a person asked (``confirm``), then the TCP leaves the hole along its axis and goes to
        ``pose``.

        Clears a latched fault (libfranka's automatic error recovery, or a reconnection after a
        lost connection, then a new control loop). Raises :class:`LimitViolation` if ``pose``
        is outside the workspace (nothing moves) or is not reached within the tolerance.
        """
        self.params.limits.check_target(pose.pos, "reset pose")
        if controller is not None:
            self.controller_spec = controller
        if self._loop.fault is not None or not self._loop.running:
            self._restart()
            self._let_go_at = None
        stiff = np.asarray(self.params.reset_stiffness, dtype=float)
        start, soft = self._let_go_at or self._let_go()
        self._let_go_at = None
        if self.grasp is not None:  # the part at rest in the hole, the skill's press let go
            self.grasp.check()
        if self.confirm is not None:
            self.confirm(pose)
        self._move_to(start, pose, stiff, soft)
        self._settle(pose)
        tick = self._loop.tick
        bias = np.zeros(6)
        for _ in range(self.params.bias_ticks):
            bias += self.step(1).wrench + tick.bias
        tick.bias = bias / self.params.bias_ticks
        tick.q_rest = self._loop.q.copy()
        self._update_mass(self._loop.raw, tick)
        law = make_law(self.controller_spec, self._mass, self.control_period)
        self._loop.install(law, ImpedanceCommand.hold(pose), restart_clock=True)
        self.step(1)  # this tick may have begun before the install: the next one adopted it
        self.resets += 1
        return self.step(1)

    @staticmethod
    def teacher_hints(task: Task) -> TeacherHints:
        """None: the simulated teacher drives no real arm (a person guides it)."""
        return NO_TEACHER_HINTS

    def finish_execution(self) -> None:
        """End the skill's control the moment its execution ends (:meth:`_let_go`), not when
        the next :meth:`reset` comes: meanwhile the caller judges, logs and prints, and the
        skill's press ran on 10-23 ms on the peg twin, 2-4 mm deeper at 0.19 m/s with 4 mm
        left to the hole's bottom. A fault (now or during the release) stays latched for
        :meth:`reset` to recover from; a command after this one cancels it."""
        if self._loop.fault is not None or not self._loop.running:
            return
        try:
            self._let_go_at = self._let_go()
        except RobotFault:
            self._let_go_at = None

    def close(self) -> None:
        """Finish the control loop (the arm holds where it is) and release the connection."""
        self._loop.finish()
        self.grasp = None  # drops the gripper's connection
        sys.setswitchinterval(self._switch_interval)
        gc.unfreeze()
        priority.restore(self._caller_class)
        robot, self._robot = self._robot, None
        if robot is not None:
            try:
                robot.stop()
            except Exception:  # noqa: BLE001 - best effort on a robot already gone
                pass

    def __enter__(self) -> FrankaRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def tap(self, every: int) -> None:
        """Sample the state every ``every`` ticks *in the control thread* (lossless however
        late the caller's thread runs) until :meth:`untap`; used by kinesthetic recording."""
        self._loop.tap(every)

    def untap(self) -> list[RobotState]:
        """Stop sampling and return the states sampled since :meth:`tap`."""
        return self._loop.untap()

    # ------------------------------------------------------------------ inspection
    @property
    def law(self) -> Controller | None:
        """The control law running in the loop (inspection and tests)."""
        return self._loop.law

    @property
    def apparent_mass(self) -> np.ndarray:
        """The apparent mass/inertia (6,) (kg, kg·m², world axes) the law's damping uses."""
        return self._mass.copy()

    @property
    def running(self) -> bool:
        """Whether the control loop runs."""
        return self._loop.running

    @property
    def thread_class(self) -> ThreadClass:
        """The control thread's scheduling class (``SCHED_FIFO 99`` when real time is enforced)."""
        return self._loop.thread_class

    @property
    def ticks(self) -> int:
        """Control ticks run since the driver connected."""
        return self._loop.ticks

    @property
    def joint_positions(self) -> np.ndarray:
        """The last measured joint angles (7,) (rad)."""
        return self._loop.q.copy()

    @property
    def compute_times(self) -> np.ndarray:
        """Ring buffer of per-tick compute times (s), indexed by tick modulo its length."""
        return self._loop.compute_times

    @property
    def read_gaps(self) -> np.ndarray:
        """Ring buffer of robot time between consecutive states read (s)."""
        return self._loop.read_gaps

    def timing_since(self, tick: int) -> tuple[np.ndarray, np.ndarray]:
        """Compute times and read gaps (s) of the ticks run since tick count ``tick``
        (:attr:`ticks`), oldest first; the last ring buffer's worth at most."""
        size = len(self._loop.compute_times)
        n = max(min(self.ticks - tick, self.ticks, size), 0)
        idx = np.arange(self.ticks - n, self.ticks) % size
        return self._loop.compute_times[idx], self._loop.read_gaps[idx]

    # ------------------------------------------------------------------ stopping
    def stop(self) -> None:
        """Hold the TCP where it is for ``stop_hold`` s, then finish the motion (Ctrl-C path)."""
        loop = self._loop
        if loop.fault is None and loop.latest is not None:
            stiff = np.asarray(self.params.reset_stiffness, dtype=float)
            loop.post(self._hold(loop.latest.pose, stiff))
            try:
                loop.wait(int(self.params.stop_hold / self.control_period), 1.0)
            except RobotFault:
                pass
        loop.finish()
        if loop.fault is None:
            loop.fault = RobotFault("the control loop was stopped (Ctrl-C); reset() to go on")

    # ------------------------------------------------------------------ internals
    def _let_go(self) -> tuple[Pose, np.ndarray]:
        """End the skill's control: a TCP below the hole's clearance plane is released
        (:meth:`_release`), any other held where it is at the reset's stiffness. The pose to
        start the reset's legs from, and the stiffness of the way out of the hole."""
        cell, stiff = self.params.reset_cell, np.asarray(self.params.reset_stiffness, float)
        start = self.state().pose
        if cell is not None and reset_via_points(start, start, cell)[0][0] == "out":
            return self._release(cell), leave_stiffness(cell, float(stiff[2]))
        self._loop.install(self._approach_law(), self._hold(start, stiff))
        return start, stiff

    def _move_to(self, start: Pose, pose: Pose, stiff: np.ndarray, soft: np.ndarray) -> None:
        """The reset's legs from ``start`` (where :meth:`_let_go` left the TCP): out of the hole
        along its axis at ``soft`` (the lateral force watched), then over and down to ``pose``
        at ``stiff`` (:mod:`~teachfit.robot.franka.reset_path`)."""
        lim, guard = self.params.limits, self.reset_guard
        for leg, end in reset_via_points(start, pose, self.params.reset_cell):
            k = soft if leg == "out" else stiff
            for waypoint in approach_waypoints(
                start, end, lim.reset_speed, lim.reset_ang_speed, 0.01
            ):
                self.command(self._hold(waypoint, k))
                state = self.step(10)
                if guard is not None and leg == "out":
                    guard.watch(state.wrench)
            start = end
        if guard is not None:
            guard.finish()

    def _release(self, cell: ResetCell) -> Pose:
        """Take over from the skill where the TCP is (its press let go at once): brake a part
        still sliding in along the hole's axis alone, its set-point moved every tick, then hold
        until the TCP is at rest (at least and at most ``cell.release_time`` after the brake;
        :func:`~teachfit.robot.franka.reset_path.release_command`), the lateral force watched
        (from the reading at the take-over: :class:`ResetGuard`); the pose it settled at.

        The state the brake starts from is read last, just before the release is installed:
        the skill's press runs on until then, and at 0.2 m/s every tick late is 0.2 mm less
        room before the hole's bottom. The brake's set-points are for the robot's time (its
        ticks since the release), not for this thread's steps: a caller that falls behind the
        1 kHz loop skips set-points rather than sending old ones (a 2-4 ms lag per set-point
        raised the lateral peak from 2.9 N to 7.1-8.9 N on the twin)."""
        lim, tick = self.params.limits, self.control_period
        inertia = self._inertia()
        decel = brake_decel(cell, inertia, lim.max_force, lim.max_torque)
        least, most = (int(round(t / (10 * tick))) for t in cell.release_time)
        axis = cell.hole2world.rotation.apply([0.0, 0.0, 1.0])
        state = self.state()
        here, speed = state.pose, float(state.lin_vel @ axis)
        first = release_command(cell, here, speed, inertia, decel, 0.0)
        lim.check_command(first)
        start = self._loop.ticks  # the release is adopted at the next tick: its time 0
        self._loop.install(self._approach_law(), first)
        if self.reset_guard is not None:
            self.reset_guard.take_over(state.wrench)
        braking, n, watched = int(np.ceil(brake_time(speed, decel) / tick)), 0, 0
        while n < braking:  # the brake: a new set-point every tick
            state = self.step(1)
            n = self._loop.ticks - start  # the robot's ticks, should this thread fall behind
            self.command(release_command(cell, here, speed, inertia, decel, n * tick))
            if self.reset_guard is not None and n // 10 > watched:
                watched = n // 10
                self.reset_guard.watch(state.wrench, n * tick <= cell.handover_time + 1e-9)
        stopped = self._loop.ticks
        while True:  # held where it stopped until at rest
            state = self.step(10)
            held = self._loop.ticks - stopped
            if self.reset_guard is not None:
                t = (self._loop.ticks - start) * tick
                self.reset_guard.watch(state.wrench, t <= cell.handover_time + 1e-9)
            still = np.linalg.norm(state.lin_vel) < 0.002 and np.linalg.norm(state.ang_vel) < 0.02
            if (held >= 10 * least and still) or held >= 10 * max(most, 1):
                break
        return Pose(state.pos.copy(), state.quat.copy())

    def _inertia(self) -> np.ndarray:
        """The TCP's operational-space inertia (6, 6) (world; kg, kg·m, kg·m²) at the last
        tick's pose, from libfranka's mass matrix with the motors' rotor inertia added."""
        tick = self._loop.tick
        mass = np.asarray(self._model.mass(self._loop.raw), dtype=float).reshape(7, 7, order="F")
        return operational_inertia(mass + np.diag(ROTOR_INERTIA), tick.jacobian, tick.r_wo)

    def _hold(self, pose: Pose, stiffness: np.ndarray) -> ImpedanceCommand:
        return ImpedanceCommand.hold(pose, stiffness=stiffness, expires_after=1.0)

    def _approach_law(self) -> Controller:
        lim = self.params.limits
        spec = FixedGainSpec(
            ImpedanceLimits(lim.max_force, lim.max_torque, lim.reset_speed, lim.reset_ang_speed)
        )
        return make_law(spec, self._mass, self.control_period)

    def _settle(self, pose: Pose) -> None:
        tol_p, tol_r = self.params.reset_tolerance
        target = wxyz_to_rotation(pose.quat).inv()
        for _ in range(int(self.params.settle_timeout / 0.01)):
            s = self.step(10)
            dp = float(np.linalg.norm(s.pos - pose.pos))
            dr = float((target * wxyz_to_rotation(s.quat)).magnitude())
            if dp < tol_p and dr < tol_r and np.linalg.norm(s.lin_vel) < 0.005:
                return
        raise LimitViolation(
            f"reset did not reach {np.round(pose.pos, 4).tolist()} within {tol_p} m / "
            f"{tol_r} rad (at {np.round(s.pos, 4).tolist()}: {dp:.4f} m, {dr:.3f} rad)"
        )

    def _connect(self) -> None:
        pf = self._pf
        probe(self.host, self.params.connect_timeout)  # bounded: the connect below is not
        try:
            self._robot = pf.Robot(self.host, self._realtime)  # caller to SCHED_FIFO if allowed
            self._model = self._robot.load_model()
        except (pf.NetworkException, RuntimeError) as exc:
            raise ConnectionLost(f"cannot connect to the Franka at {self.host}: {exc}") from exc

    def _restart(self) -> None:
        lost = isinstance(self._loop.fault, ConnectionLost) or self._robot is None
        self._loop.finish()
        if lost:
            self._connect()
        else:
            try:
                self._robot.automatic_error_recovery()
            except Exception as exc:  # noqa: BLE001 - any failure here is a robot fault
                raise fault_from(exc, self._loop.robot) from exc
        self._start()

    def _start(self) -> None:
        """Start a control loop holding the current pose."""
        try:
            first = self._robot.read_once()
        except Exception as exc:  # noqa: BLE001
            raise fault_from(exc, self._loop.robot) from exc
        self.robot_mode = str(first.robot_mode).split(".")[-1]
        tick = self._loop.tick
        tick.kinematics(first, self._model)
        self._set_reflex(first, tick.jacobian)
        self._set_load(first)
        self._update_mass(first, tick)
        tick.q_rest = np.asarray(first.q, dtype=float)
        here = Pose(tick.pos.copy(), tick.quat.copy())
        law = self._approach_law()
        stiff = np.asarray(self.params.reset_stiffness, dtype=float)
        law.set_command(self._hold(here, stiff), self._loop.t_abs)
        self._loop.start(self._robot, self._model, first, law)

    def _set_reflex(self, first: Any, jacobian: np.ndarray) -> None:
        """Send the collision thresholds (:mod:`~teachfit.robot.franka.reflex`) for the pose of
        ``first`` (a state read while the robot is idle: the firmware takes them only then)."""
        k_lever = col_major(first.EE_T_K)[:3, 3] - self.params.frames.ee2tcp.pos
        self.reflex = reflex_thresholds(
            self.params.limits, jacobian, float(np.linalg.norm(k_lever)), self.params.reflex_force
        )
        try:
            self.reflex.send(self._robot)
        except Exception as exc:  # noqa: BLE001 - a refusal is a robot fault
            raise fault_from(exc, self._loop.robot) from exc

    def _set_load(self, first: Any) -> None:
        """Send ``params.load`` (the held part) as the firmware's load, for where the TCP sits
        on the flange (``F_T_EE`` of ``first``, then ``frames.ee2tcp``)."""
        load = self.params.load
        if load is None:
            return
        f_t_tcp = col_major(first.F_T_EE) @ self.params.frames.matrices()[1]
        try:
            self._robot.set_load(*load.in_flange(f_t_tcp))
        except Exception as exc:  # noqa: BLE001 - a refusal is a robot fault
            raise fault_from(exc, self._loop.robot) from exc

    def _update_mass(self, raw: Any, tick: TorqueTick) -> None:
        """The apparent mass (6,) for the law at the pose of ``raw`` (a pylibfranka state; the
        tick's Jacobian of that pose), unless ``params.apparent_mass`` fixes it."""
        if self.params.apparent_mass is None:
            mass = np.asarray(self._model.mass(raw), dtype=float).reshape(7, 7, order="F")
            lam = operational_mass(mass, tick.jacobian, tick.r_wo)
            self._mass = np.maximum(lam, MIN_APPARENT_MASS)
