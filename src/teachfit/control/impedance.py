"""Cartesian impedance control with a superposed feed-forward wrench (Ehlers et al. 2019, eqs. 8-9).

    f_c   = K_p e_p + D_p de_p + f_ff
    tau_c = K_th e_th + D_th de_th + tau_ff

with ``e_p = x_d(t) - x`` (m), ``e_th`` the rotation vector of ``q_d q^-1`` (rad, world frame),
``de`` the twist errors, all in the world frame at the TCP. ``x_d(t)`` is extrapolated from the
last command with its desired twist, so commands may arrive slower than the 1 kHz control rate.
The commanded wrench is clipped to ``max_force`` / ``max_torque``; the desired speeds to
``max_speed`` / ``max_ang_speed``. A robot turns the wrench into joint torques (``J^T f``) or,
for the floating tool, applies it directly.

The classes here are the reference and the law of the real Franka's loop; the simulated robots
run the same law compiled (:func:`teachfit.control.compiled.fixed_law`), with MuJoCo's
quaternion routines for :mod:`teachfit.core.geometry`'s (tests check both agree).
"""

from __future__ import annotations

import math

import numpy as np

from teachfit.core.control import ImpedanceLimits
from teachfit.core.errors import ControlError
from teachfit.core.geometry import (
    quat_diff_into,
    quat_integrate_into,
    quat_rotate_into,
)
from teachfit.core.state import ImpedanceCommand


def clipped_twist(cmd: ImpedanceCommand, limits: ImpedanceLimits) -> np.ndarray:
    """The command's desired twist (6,) with speeds clipped to ``max_speed``/``max_ang_speed``."""
    out = np.concatenate([cmd.lin_vel, cmd.ang_vel])
    for sl, cap in ((slice(0, 3), limits.max_speed), (slice(3, 6), limits.max_ang_speed)):
        part = out[sl]
        norm = math.sqrt(float(part.dot(part)))  # = np.linalg.norm, without its dispatch
        if norm > cap:
            part *= cap / norm
    return out


def critical_damping(stiffness: np.ndarray, mass: np.ndarray, ratio: float) -> np.ndarray:
    """Damping ``D = 2 ratio M^1/2 sqrtm(M^-1/2 K M^-1/2) M^1/2`` for (6, 6) ``K``, (6,) ``M``."""
    sm = np.sqrt(mass)
    diag = np.diagonal(stiffness)
    if np.count_nonzero(stiffness) == np.count_nonzero(diag):  # diagonal: per axis, no eigh
        return np.diag(2.0 * ratio * np.sqrt(np.clip(diag, 0.0, None)) * sm)
    scaled = stiffness / np.outer(sm, sm)
    w, v = np.linalg.eigh(scaled)
    root = (v * np.sqrt(np.clip(w, 0.0, None))) @ v.T
    return 2.0 * ratio * root * np.outer(sm, sm)


class DampingMemo:
    """:func:`critical_damping` for a fixed apparent ``mass`` (6,), remembered for the last
    stiffness and ratio: a skill sends the same gains for many 10 ms commands in a row, and
    the (6, 6) case costs an ``eigh`` each time. Same bits as calling the function."""

    def __init__(self, mass: np.ndarray) -> None:
        self.mass = mass
        self._key = b""
        self._d = np.zeros((6, 6))

    def __call__(self, stiffness: np.ndarray, ratio: float) -> np.ndarray:
        key = stiffness.tobytes() + np.float64(ratio).tobytes()
        if key != self._key:
            self._d = critical_damping(stiffness, self.mass, ratio)
            self._key = key
        return self._d


def aligned_stiffness(
    direction: np.ndarray,
    along: float,
    across: float,
    z: float,
    rotational: float | np.ndarray = 50.0,
) -> np.ndarray:
    """A (6, 6) stiffness that is ``along`` N/m in the x-y ``direction`` of motion, ``across``
    N/m perpendicular to it in the plane, ``z`` N/m vertically, and ``rotational`` N·m/rad.

    High stiffness along the motion tracks the search path; low stiffness across it lets the
    part fall into a hole it passes over (Ehlers et al. 2019, Sec. III-D).
    """
    d = np.asarray(direction, dtype=float)[:2]
    n = float(np.hypot(d[0], d[1]))
    u = d / n if n > 1e-12 else np.array([1.0, 0.0])
    k_xy = across * np.eye(2) + (along - across) * np.outer(u, u)
    out = np.zeros((6, 6))
    out[:2, :2] = k_xy
    out[2, 2] = z
    out[3:, 3:] = np.diag(np.broadcast_to(np.asarray(rotational, dtype=float), (3,)))
    return out


class SetpointError:
    """Pose and twist errors to a command's set-point, extrapolated with its twist.

    ``x_d(t) = x_d + v_d (t - t_0)`` and ``q_d(t) = q_d ⊗ exp(ω_d (t - t_0))``; the errors are
    ``e = [x_d(t) - x; r]`` with ``q ⊗ exp(r_tool) = q_d(t)`` and ``r`` the rotation vector in the
    world frame, and ``de = v_d - [v; ω]`` (m, rad, m/s, rad/s, world frame at the TCP). Shared by
    the fixed-gain and the adaptive controller; buffers are allocated once (1 kHz path).

    The command expires ``expires_after`` s after ``t_0``: from then on ``t - t_0`` is held at
    ``expires_after`` and ``v_d = 0`` (the set-point stays where it got to; ``lapsed`` is set).
    """

    def __init__(self) -> None:
        self.err = np.zeros(6)
        self.derr = np.zeros(6)
        self._xd = np.zeros(3)
        self._qd = np.array([1.0, 0.0, 0.0, 0.0])
        self._vd = np.zeros(6)
        self._t0 = 0.0
        self._expiry = np.inf
        #: the last command expired: its set-point is held where it got to
        self.lapsed = False
        self._qtmp = np.zeros(4)
        self._rtmp = np.zeros(3)
        self._spinning = False

    def set(self, cmd: ImpedanceCommand, twist: np.ndarray, t: float) -> None:
        """Adopt ``cmd``'s set-point with the (already limited) desired ``twist`` (6,) at ``t``."""
        self._vd[:] = twist
        self._spinning = bool(self._vd[3:].any())  # nonzero (NaN too), as np.any(!= 0)
        self._xd[:] = cmd.pos
        self._qd[:] = cmd.quat
        self._t0 = t
        self._expiry = t + cmd.expires_after
        self.lapsed = False

    def update(
        self, t: float, pos: np.ndarray, quat: np.ndarray, lin_vel: np.ndarray, ang_vel: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(e, de)`` (6,) each at time ``t``; views of buffers overwritten by the next call."""
        dt = t - self._t0
        if t > self._expiry:  # hold the set-point where the expired command left it
            dt = self._expiry - self._t0
            self._xd += self._vd[:3] * dt
            if self._spinning:
                quat_integrate_into(self._qd, self._vd[3:], dt)
            self._vd[:] = 0.0
            self._spinning = False
            self._t0 = t
            self._expiry = np.inf
            self.lapsed = True
            dt = 0.0
        err, derr = self.err, self.derr
        np.subtract(self._xd, pos, out=err[:3])
        err[:3] += self._vd[:3] * dt
        qd = self._qd
        if self._spinning:
            qd = self._qtmp
            qd[:] = self._qd
            quat_integrate_into(qd, self._vd[3:], dt)
        # rotation vector r with q * exp(r) = q_d (tool frame), then expressed in the world
        quat_diff_into(self._rtmp, qd, quat)
        quat_rotate_into(err[3:], quat, self._rtmp)
        np.subtract(self._vd[:3], lin_vel, out=derr[:3])
        np.subtract(self._vd[3:], ang_vel, out=derr[3:])
        return err, derr


def clip_wrench(w: np.ndarray, limits: ImpedanceLimits) -> np.ndarray:
    """Scale force and torque of ``w`` (6,) in place to at most the limits' norms; returns w."""
    fn = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    if fn > limits.max_force:
        w[:3] *= limits.max_force / fn
    tn = np.sqrt(w[3] * w[3] + w[4] * w[4] + w[5] * w[5])
    if tn > limits.max_torque:
        w[3:] *= limits.max_torque / tn
    return w


class CartesianImpedance:
    """Cartesian impedance controller; see the module docstring for the law.

    Parameters
    ----------
    apparent_mass : (6,) array
        Apparent mass / inertia of the tool per axis (kg, kg·m²), used for critical damping.
    limits : ImpedanceLimits
    """

    def __init__(self, apparent_mass: np.ndarray, limits: ImpedanceLimits | None = None) -> None:
        m = np.asarray(apparent_mass, dtype=float).reshape(-1)
        if m.shape != (6,) or not np.all(m > 0):
            raise ControlError(f"apparent_mass must be 6 positive numbers, got {apparent_mass}")
        self.mass = m
        self.limits = limits or ImpedanceLimits()
        # buffers allocated once; the per-tick path below allocates as little as possible
        self._k = np.zeros((6, 6))
        self._d = np.zeros((6, 6))
        self._damping = DampingMemo(m)
        self._ff = np.zeros(6)
        self._error = SetpointError()
        self._has_cmd = False
        self.last_wrench = np.zeros(6)

    def reset(self) -> None:
        self._has_cmd = False
        self.last_wrench[:] = 0.0

    def set_command(self, cmd: ImpedanceCommand, t: float) -> None:
        """Adopt ``cmd`` at time ``t`` (s): gains are prepared here, not per tick."""
        lim = self.limits
        self._k[:] = cmd.stiffness
        if cmd.damping is None:
            self._d[:] = self._damping(self._k, cmd.damping_ratio)
        else:
            self._d[:] = cmd.damping
        self._error.set(cmd, clipped_twist(cmd, lim), t)
        self._ff[:] = cmd.wrench_ff
        self._has_cmd = True

    def compute(
        self,
        t: float,
        pos: np.ndarray,
        quat: np.ndarray,
        lin_vel: np.ndarray,
        ang_vel: np.ndarray,
    ) -> np.ndarray:
        """Commanded wrench ``[f; tau]`` (6,) in the world frame at the TCP.

        ``pos`` (3,), ``quat`` (4,) w-x-y-z, ``lin_vel`` and ``ang_vel`` (3,) in the world frame.
        """
        if not self._has_cmd:
            raise ControlError("compute() called before set_command()")
        err, derr = self._error.update(t, pos, quat, lin_vel, ang_vel)
        w = self._k @ err
        w += self._d @ derr
        w += self._ff
        clip_wrench(w, self.limits)
        self.last_wrench = w
        return w
