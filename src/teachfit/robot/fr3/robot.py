"""A torque-controlled Franka Research 3 in MuJoCo behind :class:`~teachfit.robot.interface.Robot`.

One control tick is one 1 ms physics step, split as MuJoCo intends for a controller:
``mj_step1`` (kinematics, inertia, bias forces of the current state), the torque law of
:mod:`teachfit.robot.fr3.control` writes ``ctrl``, ``mj_step2`` integrates, and the sensing of
:mod:`teachfit.robot.fr3.sensing` reads the step's torques. The tick runs compiled
(:mod:`teachfit.robot.fr3.kernel`): with the fixed-gain law a whole ``step(n)`` is one call;
another law (adaptive) is called from Python between the compiled halves of each tick.
``reset(pose)`` solves the inverse kinematics (:mod:`teachfit.robot.fr3.ik`) and places the
arm there at rest.

Faults, latched until the next :meth:`FR3Robot.reset`: a joint outside its position range or
faster than its speed limit raises :class:`~teachfit.core.errors.LimitViolation` (checked every
tick, as the FR3's firmware does); a MuJoCo warning or a NaN/inf state raises
:class:`~teachfit.core.errors.SimulationDiverged`.
"""

from __future__ import annotations

from collections import deque

import mujoco
import numpy as np

from teachfit.control import make_law
from teachfit.core.control import ControllerSpec, FixedGainSpec
from teachfit.core.errors import ControlError, LimitViolation, RobotFault, SimulationDiverged
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.core.teaching import TeacherHints
from teachfit.robot.fr3 import kernel
from teachfit.robot.fr3 import model as fr3_model
from teachfit.robot.fr3.control import TorqueImpedance, operational_inertia
from teachfit.robot.fr3.ik import IKSettings, solve_ik
from teachfit.robot.fr3.params import DQ_MAX, DTAU_MAX, Q_MAX, Q_MIN, READY_Q, TAU_MAX, FR3Params
from teachfit.robot.fr3.sensing import JointTorqueObserver, WristFT
from teachfit.robot.interface import law_fault, reseed
from teachfit.tasks.base import Task

TORQUE_TRACES = 16  # executions whose joint torques are kept (FR3Robot.torque_traces)
_UNTIMED = np.zeros(0, dtype=np.int64)
_UNLOGGED = np.zeros((0, 7))


class FR3Robot:
    """The simulated FR3: model + Cartesian impedance in joint torques + wrench sensing.

    ``params.sensor`` chooses the external-wrench measurement (``wrench_source``):
    ``"joint-torques"`` (default, as the real arm) or ``"wrist-ft"``.
    """

    name = "fr3"
    #: the blind teacher's style on every task (:meth:`teacher_hints`): joint friction loads
    #: the open-loop press (f_z swings 4.5-7.5 N with the sweep's direction), which a person
    #: pressing by feel corrects within 0.15 s; and a hand guiding the arm's few kilograms of
    #: apparent mass moves with less bandwidth than the free tool's (its wander and tremor
    #: low-passed over 0.1 s: unfiltered, their 100 Hz velocity steps shake the arm at
    #: 10-25 Hz and f_z with them; docs/notes/sensor-realism.md)
    TEACHER_HINTS = TeacherHints(press_feel=0.15, hand_smoothing=0.1)
    #: and on tasks that search in rz: the arm's yaw follows the teacher's 0.4 Hz wiggle about
    #: 2 degrees late (the floating tool's 0.3) and its joint friction stops the valleys from
    #: turning the part into line, so at the default pace the pins never meet both holes
    #: (socket3d: 0 of 6 starts in 60 s); a person guiding this heavier, stickier arm moves
    #: and turns slower
    TEACHER_RZ_HINTS = TeacherHints(speed=0.006, rz_wiggle_frequency=0.15)

    def __init__(
        self,
        task: Task,
        controller: ControllerSpec | None = None,
        params: FR3Params | None = None,
        seed: int = 0,
        ik: IKSettings | None = None,
    ) -> None:
        self.task = task
        self.params = params or FR3Params()
        self.wrench_source = self.params.sensor
        self.ik_settings = ik or IKSettings()
        self.model = fr3_model.build_fr3_model(task, self.params)
        self.data = mujoco.MjData(self.model)
        self.rng = np.random.default_rng(seed)
        flange = self._find_sites_and_joints()
        self.q_min, self.q_max = np.array(Q_MIN), np.array(Q_MAX)
        self.dq_max = np.array(DQ_MAX)
        self.controller_spec: ControllerSpec = controller or FixedGainSpec()
        self.ctl = TorqueImpedance(
            self.model,
            self.data,
            self._tcp,
            make_law(self.controller_spec, np.ones(6), self.control_period),
            np.array(TAU_MAX),
            DTAU_MAX,
            self.params.null_stiffness,
            self.params.null_damping,
        )
        self._build_sensing(flange)
        # the joints' limits and Stribeck constants, as the compiled tick takes them
        self._limits = (self.q_min, self.q_max, self.dq_max, *self.params.stribeck())
        self._warning_numbers = self.data.warning.number
        self._warnings = 0
        self._fault: RobotFault | ControlError | None = None
        self._cmd: ImpedanceCommand | None = None
        self.q_start = np.array(READY_Q)
        #: commanded joint torques of the last executions, one ``(t, tau)`` pair per reset: t
        #: (T,) s since that reset, tau (T, 7) N·m, one row at the end of each ``step`` call
        self.torque_traces: deque[tuple[np.ndarray, np.ndarray]] = deque(maxlen=TORQUE_TRACES)
        self._trace_t: list[float] = []
        self._trace_tau: list[np.ndarray] = []
        self.reset(task.contact_pose(np.zeros(2)).translated([0.0, 0.0, 0.05]))

    def _find_sites_and_joints(self) -> int:
        """Look up the TCP site (kept) and the flange site (returned); RobotFault unless the
        cell's dofs are exactly the 7 arm joints."""
        m, obj = self.model, mujoco.mjtObj
        self._tcp = mujoco.mj_name2id(m, obj.mjOBJ_SITE, fr3_model.TCP_SITE)
        flange = mujoco.mj_name2id(m, obj.mjOBJ_SITE, fr3_model.FLANGE_SITE)
        dofs = [m.jnt_dofadr[mujoco.mj_name2id(m, obj.mjOBJ_JOINT, j)] for j in fr3_model.JOINTS]
        if dofs != list(range(m.nv)) or m.nq != m.nv:
            raise RobotFault("the FR3 cell must have exactly the 7 arm joints as its dofs")
        return flange

    def _build_sensing(self, flange: int) -> None:
        """The joint-torque observer and the wrist F/T sensor at ``flange`` (a site id), the
        one ``wrench_source`` names switched on in the compiled tick, and their buffers."""
        m, d, obj = self.model, self.data, mujoco.mjtObj
        self.observer = JointTorqueObserver(
            m,
            d,
            fr3_model.JOINT_TORQUE_SENSORS,
            self.params.wrench_cutoff,
            self.params.torque_noise,
            self.rng,
            self.params.output_cutoff,
        )
        force = mujoco.mj_name2id(m, obj.mjOBJ_SENSOR, fr3_model.FT_FORCE)
        torque = mujoco.mj_name2id(m, obj.mjOBJ_SENSOR, fr3_model.FT_TORQUE)
        self.ft = WristFT(
            m, d, flange, force, torque, self.params.wrench_cutoff, self.params.output_cutoff
        )
        self._use_ft = self.wrench_source == "wrist-ft"
        if self._use_ft:  # the noise block then feeds the wrist sensor's gauges
            f_sd, t_sd = self.params.ft_noise
            self.observer.noise_std[:] = (f_sd, f_sd, f_sd, t_sd, t_sd, t_sd, 0.0)
            self.observer.draw_noise()
        sc = self.ctl.sc
        sc[kernel.ALPHA], sc[kernel.INV_DT] = self.observer.alpha, 1.0 / self.control_period
        sc[kernel.USE_FT] = float(self._use_ft)
        self._obs_bufs = (*self.observer.bufs, self.ft.adr, self.ft.filt, self.observer.coef)
        self._obs_bufs += (self.observer.tau_out, self.observer.tau_z, self.ft.out, self.ft.z)

    # ------------------------------------------------------------------ Robot protocol
    @property
    def control_period(self) -> float:
        return float(self.model.opt.timestep)

    @property
    def time(self) -> float:
        return float(self.data.time)

    @property
    def law(self) -> object:
        """The Cartesian control law in the loop (inspection and tests only)."""
        return self.ctl.law

    def reset(self, pose: Pose, controller: ControllerSpec | None = None) -> RobotState:
        """Place the arm at rest at the IK solution for TCP ``pose``; zero the wrench reading;
        from now on run ``controller`` (``None``: the current law, its state cleared)."""
        m, d = self.model, self.data
        if controller is not None:
            self.controller_spec = controller
        ik = solve_ik(m, fr3_model.TCP_SITE, pose, self.q_start, self.q_start, self.ik_settings)
        self._fault = None
        mujoco.mj_resetData(m, d)
        d.qpos[:] = ik.q
        mujoco.mj_forward(m, d)
        lam = operational_inertia(m, d, self._tcp)
        self.apparent_mass = np.diag(lam).copy()
        self.ctl.law = make_law(self.controller_spec, self.apparent_mass, self.control_period)
        self.ctl.reset(ik.q)
        d.ctrl[:] = self.ctl.tau
        mujoco.mj_forward(m, d)  # the wrist sensor now sees the arm holding itself
        self.ctl.update_kinematics()
        self.observer.reset()
        self.ctl.sc[kernel.NOISE_I] = 0.0
        self.ft.reset(d.site_xpos[self._tcp])
        self.command(ImpedanceCommand.hold(pose))
        self._warnings = int(self._warning_numbers.sum())
        self._close_trace()
        self._t_reset = float(d.time)
        return self.state()

    def _close_trace(self) -> None:
        if self._trace_t:
            self.torque_traces.append((np.array(self._trace_t), np.array(self._trace_tau)))
        self._trace_t, self._trace_tau = [], []

    def torque_trace(self) -> tuple[np.ndarray, np.ndarray]:
        """The commanded joint torques since the last reset: ``(t (T,) s, tau (T, 7) N·m)``."""
        return np.array(self._trace_t), np.array(self._trace_tau).reshape(-1, self.model.nu)

    def recent_torque_traces(self, k: int) -> list[tuple[np.ndarray, np.ndarray]]:
        """The last ``k`` executions' ``(t, tau)`` (oldest first), the current one included."""
        current = self.torque_trace()
        traces = [*self.torque_traces, *([current] if current[0].size else [])]
        return traces[-k:] if k > 0 else []

    def command(self, cmd: ImpedanceCommand) -> None:
        if self._fault is not None:
            raise self._fault
        self._cmd = cmd
        self.ctl.law.set_command(cmd, self.data.time)

    def step(self, n: int = 1) -> RobotState:
        if self._fault is not None:
            raise self._fault
        if self.ctl.compiled:
            self._run_compiled(n)
        else:
            self._run_python_law(n)
        self._check_divergence()
        self._trace_t.append(float(self.data.time) - self._t_reset)
        self._trace_tau.append(self.ctl.tau.copy())
        return self.state()

    def _run_compiled(
        self, n: int, times: np.ndarray = _UNTIMED, log: np.ndarray = _UNLOGGED
    ) -> None:
        ctl, d, sc = self.ctl, self.data, self.ctl.sc
        ctl.load_law()
        done = 0
        while done < n:
            with kernel.untimed():
                ticks, status = kernel.run_fixed(
                    n - done, d.time, ctl.fns, ctl.m_ptr, ctl.d_ptr, ctl.site, ctl.dat,
                    ctl.ctl_bufs(), ctl.law_bufs, self._obs_bufs, self._limits, sc,
                    times[done:], log[done:],
                )  # fmt: skip
            done += ticks
            if status == kernel.NOISE_EMPTY:
                self._next_noise()
            elif status == kernel.LIMIT:
                ctl.store_law()
                self._check_limits()
        ctl.store_law()

    def step_timed(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`step` ``n`` ticks of the fixed-gain law, returning each tick's law and torque
        compute time (µs, measured inside the compiled loop) and torques (n, 7) (N·m)."""
        if not self.ctl.compiled:
            raise RobotFault("step_timed needs the fixed-gain law (the compiled tick)")
        times = np.zeros(n, dtype=np.int64)
        log = np.zeros((n, self.model.nu))
        self._run_compiled(n, times, log)
        self._check_divergence()
        return times / 1e3, log

    def replay(self, log: np.ndarray) -> None:
        """The physics alone of a controlled run: one step per row of joint torques ``log``
        (n, 7) (N·m) written into ``ctrl``, the joints' Stribeck term included, no law, no
        sensing, no limit checks (compiled, :func:`teachfit.robot.fr3.kernel.replay`)."""
        ctl = self.ctl
        kernel.replay(ctl.fns, ctl.m_ptr, ctl.d_ptr, ctl.dat, self._limits, log)

    def _run_python_law(self, n: int) -> None:
        ctl, d, sc = self.ctl, self.data, self.ctl.sc
        law, fns, m_ptr, d_ptr, site = ctl.law, ctl.fns, ctl.m_ptr, ctl.d_ptr, ctl.site
        dat = ctl.dat
        bufs, obs, lim = ctl.ctl_bufs(), self._obs_bufs, self._limits
        block = len(self.observer.noise)  # obs[6], rows of the noise block
        pos, quat, v, w = ctl.pos, ctl.quat, ctl.twist[:3], ctl.twist[3:]
        for _ in range(n):
            if sc[kernel.NOISE_I] >= block:
                self._next_noise()
            kernel.tick_pre(fns, m_ptr, d_ptr, site, dat, bufs, ctl.law_bufs)
            ctl.wrench[:] = law.compute(d.time, pos, quat, v, w)
            if kernel.tick_post(fns, m_ptr, d_ptr, ctl.wrench, dat, bufs, obs, lim, sc):
                self._check_limits()

    def seed_noise(self, seed: int) -> None:
        """Restart the sensors' noise from ``seed``; the next :meth:`reset` draws its first
        block from it (:class:`~teachfit.robot.interface.NoiseSeeded`)."""
        reseed(self.rng, seed)

    def _next_noise(self) -> None:
        self.observer.draw_noise()
        self.ctl.sc[kernel.NOISE_I] = 0.0

    def state(self) -> RobotState:
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        self.ctl.update_kinematics()
        return RobotState(
            t=float(d.time),
            pos=self.ctl.pos.copy(),
            quat=self.ctl.quat.copy(),
            lin_vel=self.ctl.twist[:3].copy(),
            ang_vel=self.ctl.twist[3:].copy(),
            wrench=self.measured_wrench(),
        )

    @classmethod
    def teacher_hints(cls, task: Task) -> TeacherHints:
        """The blind teacher's style on this arm for ``task`` (``execution.teacher.style_for``):
        :data:`TEACHER_HINTS`, with :data:`TEACHER_RZ_HINTS` where ``task`` searches in rz."""
        if "rz" in task.search_dims:
            return cls.TEACHER_HINTS.then(cls.TEACHER_RZ_HINTS)
        return cls.TEACHER_HINTS

    def finish_execution(self) -> None:
        """Nothing to do: the simulation's time runs only in :meth:`step`."""

    def close(self) -> None:
        """Nothing to release but the simulator's memory (kept until garbage collection)."""
        self._cmd = None
        self._close_trace()

    def __enter__(self) -> FR3Robot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ----------------------------------------------------------------------- sensors
    def measured_wrench(self) -> np.ndarray:
        """External wrench on the tool at the TCP (N, N·m, world) from ``wrench_source``."""
        if self._use_ft:
            return self.ft.wrench(self.data.site_xpos[self._tcp])
        return self.observer.wrench(self.ctl.jac)

    @property
    def joint_torques(self) -> np.ndarray:
        """The torques commanded at the last tick (N·m, joints 1..7)."""
        return self.ctl.tau.copy()

    # ------------------------------------------------------------------------ faults
    def _check_limits(self) -> None:
        self._check_divergence()  # MuJoCo resets a diverged state: that is not a limit fault
        d = self.data
        q, dq = d.qpos, d.qvel
        bad_q = np.flatnonzero((q < self.q_min) | (q > self.q_max))
        bad_dq = np.flatnonzero(np.abs(dq) > self.dq_max)
        if not (bad_q.size or bad_dq.size):
            return
        what = [f"joint {i + 1} at {q[i]:.4f} rad outside its range" for i in bad_q]
        what += [f"joint {i + 1} at {dq[i]:.3f} rad/s over its speed limit" for i in bad_dq]
        self._fault = LimitViolation(f"{'; '.join(what)} at t={d.time:.3f} s")
        raise self._fault

    def _check_divergence(self) -> None:
        d = self.data
        count = int(self._warning_numbers.sum())
        finite = np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))
        if count > self._warnings or not finite:
            cause = law_fault(self.ctl.law, float(d.time))
            if cause is not None:
                self._warnings = count
                self._fault = cause
                raise cause
        if count > self._warnings:
            kinds = [mujoco.mjtWarning(i).name for i, w in enumerate(d.warning) if w.number > 0]
            self._warnings = count
            self._fault = SimulationDiverged(
                f"MuJoCo warning(s) {kinds} at t={d.time:.3f} s: simulation invalid"
            )
            raise self._fault
        if not (np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))):
            self._fault = SimulationDiverged(f"NaN/inf in the state at t={d.time:.3f} s")
            raise self._fault
