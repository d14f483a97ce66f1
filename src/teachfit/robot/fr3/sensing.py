"""How the FR3 measures the external wrench: from its joint torques, or with a wrist F/T sensor.

**Joint torques** (Franka's ``tau_ext_hat_filtered`` / ``O_F_ext_hat_K``). The link-side torque
sensors read what the motors transmit past the gear friction and the rotors' inertia; in MuJoCo
that is the torque sensor on a site at each joint's anchor, projected on the joint axis
(``tau_J = tau_motor - tau_f - I_rotor ddq``, exactly). The
model of the arm predicts the torque that motion needs, ``tau_model = M(q) ddq + c(q, dq)``, so
the external joint torque is ``tau_ext = tau_model - tau_J`` (what the environment adds). Its
discrete generalized-momentum observer (De Luca and Mattone 2005, ``p = M dq``,
``r_k = r_{k-1} + K_O dt ((p_k - p_{k-1}) / dt - (tau_J - c + dM dq) - r_{k-1})``) is, with the
momentum step written out, the first-order low-pass

    r_k = r_{k-1} + a (M (dq_k - dq_{k-1}) / dt + c_{k-1} - tau_J,{k-1} - r_{k-1}),
    a = 1 - exp(-2 pi f_c dt)

(N·m), which is what is implemented (``f_c = wrench_cutoff``; ``M`` is the links' inertia: the
full joint-space inertia less the rotors' armature, whose torque the sensors do not see; the
arithmetic runs compiled every tick, :func:`teachfit.robot.fr3.kernel.observe`). The TCP
wrench is the least-squares solution of ``J^T F = r``: ``F = pinv(J^T) r`` (N, N·m, world
frame at the TCP), the wrench the environment exerts on the tool. The sensors carry white
noise of ``torque_noise`` N·m per tick.

**Wrist F/T sensor**: MuJoCo's force and torque sensors on a site at the flange (the interface
between link 7 and the hand), filtered by the same first-order low-pass, tared at reset (the
hand and part's weight), turned into the environment's wrench at the TCP as on the floating
tool. Its gauges carry white noise of ``ft_noise`` (N, N·m) per tick, inside the filters.

**Output filter.** Either estimate then passes a second-order Butterworth low-pass
(``FR3Params.output_cutoff``, :mod:`teachfit.robot.sensor_filter`), as Franka filters
``O_F_ext_hat_K`` and ATI's Net F/T filters on the device before anything reads it at 100 Hz:
the 100 Hz log and the skills read a signal without aliased kHz content.
"""

from __future__ import annotations

import mujoco
import numpy as np

from teachfit.robot.sensor_filter import butterworth2

_NOISE_BLOCK = 1000  # sensor noise drawn this many ticks at a time


def lowpass_alpha(cutoff: float, dt: float) -> float:
    """Smoothing factor of a first-order low-pass of ``cutoff`` Hz sampled every ``dt`` s."""
    return 1.0 - float(np.exp(-2.0 * np.pi * cutoff * dt))


class JointTorqueObserver:
    """External joint torques from the joint torque sensors and the arm's model (see module).

    ``sensors``: the names of the joint torque sensors, one per dof in dof order.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        sensors: tuple[str, ...],
        cutoff: float,
        noise: float,
        rng: np.random.Generator,
        output_cutoff: float = 18.0,
    ) -> None:
        nv = model.nv
        if nv != model.njnt or len(sensors) != nv:
            raise ValueError("the observer expects one dof per joint and a sensor per joint")
        self.alpha = lowpass_alpha(cutoff, float(model.opt.timestep))
        self.coef = butterworth2(output_cutoff, float(model.opt.timestep))
        #: per-channel noise std of the block (N·m; the robot sets the wrist sensor's instead)
        self.noise_std, self.rng = np.full(nv, float(noise)), rng
        self.tau_ext = np.zeros(nv)
        self.tau_out = np.zeros(nv)  # after the output filter: what the robot reports
        self.tau_z = np.zeros((2, nv))
        self.noise = np.zeros((_NOISE_BLOCK, nv))
        ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, s) for s in sensors]
        adr = np.array([model.sensor_adr[i] for i in ids], dtype=np.int64)
        axes = np.array([model.jnt_axis[model.dof_jntid[i]] for i in range(nv)])
        # dq_prev, ddq, M ddq, sensor addresses, joint axes, armature, noise, tau_ext (kernel order)
        self.bufs: tuple[np.ndarray, ...] = (np.zeros(nv), np.zeros(nv), np.zeros(nv), adr, axes)
        self.bufs += (model.dof_armature.copy(), self.noise, self.tau_ext)
        self.draw_noise()

    def reset(self) -> None:
        self.tau_ext[:] = 0.0
        self.tau_out[:] = 0.0
        self.tau_z[:] = 0.0
        self.draw_noise()

    def draw_noise(self) -> None:
        """The next block of sensor noise (the kernel walks through it, ``NOISE_I``)."""
        self.noise[:] = self.rng.normal(0.0, 1.0, self.noise.shape) * self.noise_std

    def wrench(self, jac: np.ndarray) -> np.ndarray:
        """``F = pinv(J^T) tau_ext`` (6,) for the TCP Jacobian ``jac`` (6, nv)."""
        return np.linalg.lstsq(jac.T, self.tau_out, rcond=None)[0]


class WristFT:
    """A wrist F/T sensor from MuJoCo force/torque sensors at the flange site (see module)."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        site: int,
        force_sensor: int,
        torque_sensor: int,
        cutoff: float,
        output_cutoff: float = 18.0,
    ) -> None:
        f_adr = int(model.sensor_adr[force_sensor])
        if int(model.sensor_adr[torque_sensor]) != f_adr + 3:
            raise ValueError("force and torque sensors must be adjacent")
        self.data, self.site, self.adr = data, site, f_adr
        self.raw = data.sensordata[f_adr : f_adr + 6]
        self.filt = np.zeros(6)
        self.alpha = lowpass_alpha(cutoff, float(model.opt.timestep))
        self.coef = butterworth2(output_cutoff, float(model.opt.timestep))
        self.out = np.zeros(6)  # after the output filter: what the robot reports
        self.z = np.zeros((2, 6))
        self.tare = np.zeros(6)

    def reset(self, tcp: np.ndarray) -> None:
        """Start the filter at the current reading and tare it (``wrench(tcp)`` reads zero)."""
        self.filt[:] = self.raw
        b0, b1, b2, a1, a2 = self.coef
        self.out[:] = self.raw  # the output filter at rest there
        self.z[1] = (b2 - a2) * self.raw
        self.z[0] = (b1 - a1) * self.raw + self.z[1]
        self.tare[:] = 0.0
        self.tare[:] = self.wrench(tcp)

    def wrench(self, tcp: np.ndarray) -> np.ndarray:
        """Tared environment wrench on the tool at the TCP ``tcp`` (3,) (world frame)."""
        d = self.data
        rot = d.site_xmat[self.site].reshape(3, 3)
        # MuJoCo reports what the hand exerts on link 7; the environment's wrench on the tool
        # balances it quasi-statically: flip the sign, then move the torque to the TCP
        f_env = -(rot @ self.out[:3])
        t_env = -(rot @ self.out[3:]) + np.cross(d.site_xpos[self.site] - tcp, f_env)
        return np.concatenate([f_env, t_env]) - self.tare
