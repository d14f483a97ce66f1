"""A floating tool: a 6-DOF body driven by a commanded wrench, with a wrist F/T sensor.

This is the simulated robot behind :class:`~teachfit.robot.interface.Robot`. The tool body
(free joint, gravity compensated like a torque-controlled arm's payload) carries the task's
held part on a child body; MuJoCo force/torque sensors between the two play the wrist F/T
sensor. Each control tick (one 1 ms physics step) the controller's wrench at the TCP is applied
with ``mj_applyFT``. For the two laws of :mod:`teachfit.control` the ticks of a ``step(n)`` run
compiled (:mod:`teachfit.robot.floating_kernel`); any other law runs them in Python.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import mujoco
import numpy as np

from teachfit.control import make_law
from teachfit.core.control import ControllerSpec, FixedGainSpec
from teachfit.core.errors import ControlError, SimulationDiverged
from teachfit.core.geometry import Pose
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.core.teaching import NO_TEACHER_HINTS, TeacherHints
from teachfit.robot.floating_kernel import FloatingKernel
from teachfit.robot.interface import law_fault, reseed
from teachfit.robot.sensor_filter import LowPass2
from teachfit.tasks.base import Task
from teachfit.tasks.scene.mjcf import ContactParams, SceneXml, fmt


@dataclass(frozen=True)
class FloatingToolParams:
    """Tool dynamics and wrist sensor model.

    ``mass`` (kg) and ``inertia`` (kg·m², diagonal) are the apparent inertia the controller
    moves (a light arm's end-effector). The wrist sensor is modelled as an ATI Mini45 on a Net
    F/T (Ehlers et al.'s): its gauges are sampled every physics tick (1 kHz here; 7 kHz on the real
    one) with white noise of ``ft_noise`` (N, N·m, standard deviation per unfiltered sample,
    of the order of the Mini45's documented resolution), then low-pass filtered on the device
    (``ft_cutoff`` Hz, a second-order Butterworth, one of the Net F/T's selectable cutoffs:
    :mod:`teachfit.robot.sensor_filter`); what the 100 Hz log and the skills read is that
    filtered output. ``ft_bias`` is a constant offset; readings are tared at reset.
    """

    mass: float = 1.0
    inertia: tuple[float, float, float] = (0.004, 0.004, 0.004)
    ft_noise: tuple[float, float] = (0.05, 0.002)
    ft_bias: tuple[float, float, float, float, float, float] = (0.0,) * 6
    ft_cutoff: float = 18.0
    timestep: float = 0.001
    contact: ContactParams = field(default_factory=ContactParams)

    def __post_init__(self) -> None:
        if not self.mass > 0 or min(self.inertia) <= 0:
            raise ControlError("tool mass and inertia must be positive")
        if min(self.ft_noise) < 0:
            raise ControlError("ft_noise must be >= 0")
        if not 0 < self.ft_cutoff < 0.5 / self.timestep:
            raise ControlError("ft_cutoff must be within (0 Hz, the physics rate's Nyquist)")
        if not 0 < self.timestep <= 0.002:
            raise ControlError("timestep must be within (0, 2 ms]")

    @property
    def apparent_mass(self) -> np.ndarray:
        return np.array([self.mass] * 3 + list(self.inertia))


def build_scene(task: Task, params: FloatingToolParams | None = None) -> str:
    """MJCF of ``task``'s cell with a floating tool holding the task's part."""
    params = params or FloatingToolParams()
    contact = getattr(task.scene, "contact", None) or params.contact
    scene = SceneXml(model=f"teachfit-{task.name}", timestep=params.timestep)
    scene.option.set("noslip_iterations", "0")
    ET.SubElement(
        scene.worldbody, "light", pos="0.3 -0.3 0.8", dir="-0.4 0.4 -1", diffuse=".8 .8 .8"
    )
    ET.SubElement(
        scene.worldbody, "light", pos="-0.3 0.3 0.9", dir="0.3 -0.3 -1", diffuse=".4 .4 .4"
    )
    ET.SubElement(
        scene.worldbody,
        "geom",
        name="floor",
        type="plane",
        size="0.5 0.5 0.01",
        material="grid",
        contype="0",
        conaffinity="0",
    )
    task.scene.add_fixture(scene, contact)
    length = task.scene.held_part_length
    start = task.contact_pose(np.array([0.05, 0.0])).translated([0, 0, 0.02])
    tool = ET.SubElement(scene.worldbody, "body", name="tool", pos=fmt(start.pos), gravcomp="1")
    ET.SubElement(tool, "freejoint", name="tool_free")
    ET.SubElement(
        tool,
        "inertial",
        pos=fmt([0, 0, length + 0.02]),
        mass=fmt(params.mass),
        diaginertia=fmt(params.inertia),
    )
    ET.SubElement(tool, "site", name="tcp", size="0.002", rgba="0 1 0 1")
    ET.SubElement(
        tool,
        "geom",
        name="flange",
        type="cylinder",
        size=fmt([0.03, 0.01]),
        pos=fmt([0, 0, length + 0.02]),
        material="dark",
        contype="0",
        conaffinity="0",
        mass="0",
    )
    part = ET.SubElement(tool, "body", name="held_part", gravcomp="1")
    task.scene.add_held_part(part, scene, contact)
    ET.SubElement(part, "site", name="ft_site", pos=fmt([0, 0, length]), size="0.003")
    ET.SubElement(scene.sensor, "force", name="ft_force", site="ft_site")
    ET.SubElement(scene.sensor, "torque", name="ft_torque", site="ft_site")
    return scene.to_string()


class FloatingToolRobot:
    """The simulated robot: MuJoCo floating tool + control law + wrist F/T sensor.

    Implements :class:`~teachfit.robot.interface.Robot`. One control tick is one physics step.
    The control law is built from ``controller`` (data; default fixed-gain impedance) and
    replaced by the one a :meth:`reset` names.
    """

    name = "floating"
    wrench_source = "wrist-ft"

    def __init__(
        self,
        task: Task,
        controller: ControllerSpec | None = None,
        params: FloatingToolParams | None = None,
        seed: int = 0,
    ) -> None:
        self.task = task
        self.params = params or FloatingToolParams()
        self.xml = build_scene(task, self.params)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self.controller_spec: ControllerSpec = controller or FixedGainSpec()
        self._law = make_law(self.controller_spec, self.params.apparent_mass, self.control_period)
        self.rng = np.random.default_rng(seed)
        m = self.model
        self._body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "tool")
        jnt = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "tool_free")
        self._qpos_adr = int(m.jnt_qposadr[jnt])
        self._qvel_adr = int(m.jnt_dofadr[jnt])
        self._site_ft = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "ft_site")
        f_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "ft_force")
        t_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "ft_torque")
        self._f_adr = int(m.sensor_adr[f_id])
        self._t_adr = int(m.sensor_adr[t_id])
        assert self._t_adr == self._f_adr + 3, "force and torque sensors must be adjacent"
        self._ft_raw = self.data.sensordata[self._f_adr : self._f_adr + 6]
        # views into MjData kept once: each attribute access of the bindings builds a new
        # array (~0.5-1 µs, several per 10 ms command)
        self._site_rot = self.data.site_xmat[self._site_ft].reshape(3, 3)
        self._site_pos = self.data.site_xpos[self._site_ft]
        self._ft_lp = LowPass2(6, self.params.ft_cutoff, float(m.opt.timestep))
        self._ft_filt = self._ft_lp.out
        self._ft_sd = np.repeat(np.asarray(self.params.ft_noise, dtype=float), 3)
        self._gauges = np.zeros((10, 6))  # one step(n)'s gauge samples
        a, b = self._qpos_adr, self._qvel_adr
        self._pos = self.data.qpos[a : a + 3]
        self._quat = self.data.qpos[a + 3 : a + 7]
        self._linvel = self.data.qvel[b : b + 3]
        self._angvel_local = self.data.qvel[b + 3 : b + 6]
        self._angvel = np.zeros(3)
        self._tare = np.zeros(6)
        self._bias = np.asarray(self.params.ft_bias, dtype=float)
        self._warnings = 0
        self._warning_numbers = self.data.warning.number
        self._cmd: ImpedanceCommand | None = None
        self._fault: SimulationDiverged | ControlError | None = None
        self._kernel = self._bind_kernel()

    # ------------------------------------------------------------------ Robot protocol
    @property
    def control_period(self) -> float:
        return float(self.model.opt.timestep)

    @property
    def time(self) -> float:
        return float(self.data.time)

    def reset(self, pose: Pose, controller: ControllerSpec | None = None) -> RobotState:
        """Place the TCP at ``pose`` at rest, hold it, and tare the F/T sensor; from now on run
        ``controller`` (``None``: keep the current law, its adapted state cleared)."""
        if controller is not None:
            self.controller_spec = controller
            self._law = make_law(controller, self.params.apparent_mass, self.control_period)
            self._kernel = self._bind_kernel()
        self._fault = None
        mujoco.mj_resetData(self.model, self.data)
        self._pos[:] = pose.pos
        self._quat[:] = pose.quat
        mujoco.mj_forward(self.model, self.data)
        self._ft_lp.reset(self._ft_raw)
        self._law.reset()
        self.command(ImpedanceCommand.hold(pose))
        self._tare[:] = self._raw_wrench()  # tared at rest in free space, like a real sensor
        self._warnings = self._warning_count()
        return self.state()

    def command(self, cmd: ImpedanceCommand) -> None:
        if self._fault is not None:
            raise self._fault
        self._cmd = cmd
        self._law.set_command(cmd, self.data.time)

    @staticmethod
    def teacher_hints(task: Task) -> TeacherHints:
        """None: the blind teacher guides the free tool as the paper's teacher guided the arm."""
        return NO_TEACHER_HINTS

    def finish_execution(self) -> None:
        """Nothing to do: the simulation's time runs only in :meth:`step`."""

    def close(self) -> None:
        """Nothing to release but the simulator's memory (kept until garbage collection)."""
        self._cmd = None

    def __enter__(self) -> FloatingToolRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def law(self) -> object:
        """The control law object running in the loop (inspection and tests only)."""
        return self._law

    def _bind_kernel(self) -> FloatingKernel | None:
        """The compiled tick for the current law (None: a law only Python runs)."""
        if not FloatingKernel.supports(self._law):
            return None
        st: tuple[np.ndarray, ...] = (
            self._pos,
            self._quat,
            self._linvel,
            self._angvel_local,
            self._angvel,
        )
        st += (self.data.xpos[self._body], self.data.qfrc_applied, self.data.sensordata)
        st += (np.zeros(6),)
        return FloatingKernel(self.model, self.data, self._body, self._law, st)

    def step(self, n: int = 1) -> RobotState:
        if self._fault is not None:
            raise self._fault
        if self._gauges.shape[0] < n:
            self._gauges = np.zeros((n, 6))
        if self._kernel is None:
            self._step_python(n)
            # the gauges' samples with their noise, through the device's low-pass (one call)
            self._ft_lp.filter(self._gauges[:n] + self._noise(n))
        else:  # the same, per tick inside the compiled loop
            lp = self._ft_lp
            ft = (self._noise(n), lp.coef, lp.out, lp.zi, self._gauges[0])
            if self._kernel.step(n, self._f_adr, ft) < n:
                self._law_output_fault(self._pos, self._quat, self._linvel, self._angvel)
        self._check_divergence()
        return self.state()

    def _step_python(self, n: int) -> None:
        """``n`` ticks with the law in Python (a law the compiled tick does not know)."""
        m, d = self.model, self.data
        ctrl = self._law
        qfrc = d.qfrc_applied
        body = self._body
        pos, quat, linvel = self._pos, self._quat, self._linvel
        angvel, angvel_local = self._angvel, self._angvel_local
        raw = self._ft_raw
        gauges = self._gauges
        point = d.xpos[body]  # the tool frame origin is the TCP
        for k in range(n):
            mujoco.mju_rotVecQuat(angvel, angvel_local, quat)
            w = ctrl.compute(d.time, pos, quat, linvel, angvel)
            if not math.isfinite(float(w.sum())):
                self._law_output_fault(pos, quat, linvel, angvel)
            qfrc[:] = 0.0
            mujoco.mj_applyFT(m, d, w[:3], w[3:], point, body, qfrc)
            mujoco.mj_step(m, d)
            gauges[k] = raw  # the gauges sampled every tick

    def state(self) -> RobotState:
        return RobotState(
            t=float(self.data.time),
            pos=self._pos.copy(),
            quat=self._quat.copy(),
            lin_vel=self._linvel.copy(),
            ang_vel=self._angvel_world(),
            wrench=self.measured_wrench(),
        )

    # ----------------------------------------------------------------------- sensors
    def _angvel_world(self) -> np.ndarray:
        out = np.zeros(3)
        mujoco.mju_rotVecQuat(out, self._angvel_local, self._quat)
        return out

    def _raw_wrench(self) -> np.ndarray:
        """Environment wrench on the held part at the TCP, world frame, untared, filtered."""
        rot = self._site_rot
        f_site = self._ft_filt[:3]
        t_site = self._ft_filt[3:]
        # MuJoCo reports what the child exerts on the parent; the environment's wrench on the
        # part balances it (quasi-statically), so flip the sign, then move the torque to the TCP.
        out = np.empty(6)  # np.dot: the same BLAS call as ``@``, less dispatch
        np.negative(np.dot(rot, f_site), out=out[:3])
        np.negative(np.dot(rot, t_site), out=out[3:])
        # + lever x f_env, written out: np.cross costs ~10 small numpy calls (per command)
        lx, ly, lz = (self._site_pos - self._pos).tolist()
        fx, fy, fz = out[:3].tolist()
        out[3] += ly * fz - lz * fy
        out[4] += lz * fx - lx * fz
        out[5] += lx * fy - ly * fx
        return out

    def seed_noise(self, seed: int) -> None:
        """Restart the gauge noise from ``seed``; the next :meth:`reset` on draws from it
        (:class:`~teachfit.robot.interface.NoiseSeeded`)."""
        reseed(self.rng, seed)

    def _noise(self, n: int) -> np.ndarray:
        """(n, 6) gauge noise of ``n`` ticks, before the filter (N, N·m)."""
        return self.rng.normal(0.0, 1.0, (n, 6)) * self._ft_sd

    def measured_wrench(self) -> np.ndarray:
        """What the wrist F/T sensor reports: its filtered output, tared and biased (N, N·m,
        world, at the TCP); the gauge noise is inside the filter."""
        return self._raw_wrench() - self._tare + self._bias

    def true_contact_wrench(self) -> np.ndarray:
        """Tared wrench without the bias (for tests and diagnostics; the filtered gauge noise
        is in it unless ``ft_noise`` is zero)."""
        return self._raw_wrench() - self._tare

    # -------------------------------------------------------------------- divergence
    def _warning_count(self) -> int:
        return sum(self._warning_numbers.tolist())  # a view; a list sum beats numpy's here

    def _law_output_fault(self, *inputs: np.ndarray) -> None:
        """A non-finite wrench: the law's fault (a :class:`ControlError`) when what it was
        given was finite, else the state had diverged before it (SimulationDiverged)."""
        if all(np.all(np.isfinite(x)) for x in inputs):
            self._fault = law_fault(self._law, float(self.data.time))
        if self._fault is None:
            self._fault = SimulationDiverged(
                f"NaN/inf in the state at t={self.data.time:.3f} s: simulation invalid"
            )
        raise self._fault

    def _check_divergence(self) -> None:
        count = self._warning_count()
        if count > self._warnings:
            kinds = [
                mujoco.mjtWarning(i).name for i, w in enumerate(self.data.warning) if w.number > 0
            ]
            self._warnings = count
            self._fault = SimulationDiverged(
                f"MuJoCo warning(s) {kinds} at t={self.data.time:.3f} s: simulation invalid"
            )
            raise self._fault
        if not math.isfinite(sum(self.data.qpos.tolist()) + sum(self.data.qvel.tolist())):
            self._fault = SimulationDiverged(f"NaN/inf in the state at t={self.data.time:.3f} s")
            raise self._fault
