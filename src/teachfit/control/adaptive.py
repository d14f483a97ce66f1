"""Adaptive Cartesian impedance control (Johannsmeier et al. 2019, docs/methods.md).

The Cartesian form of Yang et al., T-RO 2011.

Per control period ``T`` and element-wise per task coordinate ``i`` (x, y, z, rx, ry, rz in the
world frame at the TCP), with ``e = x_d - x`` (m, rad: rotation vector) and ``de = dx_d - dx``
(m/s, rad/s):

    eps        = de + kappa e                                     (adaptive tracking error)
    F_ff(t)    = F_ff(t-T) + alpha (eps - gamma_a F_ff(t-T))      (adaptive feed-forward)
    K_a(t)     = K_a(t-T)  + beta  (eps e - gamma_b K_a(t-T))     (adaptive stiffness)
    K          = K_cmd + diag(K_a)
    D          = D_cmd + diag(2 xi sqrt(m) (sqrt(K_cmd,ii + K_a) - sqrt(K_cmd,ii)))
    w          = K e + D de + F_d + F_ff                          (N, N·m at the TCP)

``K_cmd`` / ``D_cmd`` / ``F_d`` come from the :class:`~teachfit.robot.interface.ImpedanceCommand`
(``F_d = wrench_ff``, the skill's own feed-forward). Every tick the increments are clipped to
``dF_max T`` / ``dK_max T`` and the states to ``|F_ff| <= F_max``, ``K_cmd,ii + K_a <= K_max``;
the output wrench is clipped like the fixed-gain controller's (:class:`ImpedanceLimits`).
The rate limits bound the *adaptation*; a step in the commanded stiffness is the skill's own
choice (a command may cut ``K_a`` at once so that ``K_cmd,ii + K_a <= K_max`` still holds).

Choice (documented here because the reconstruction is silent on it): the *command's stiffness
is the initial and minimum stiffness*. The adaptive part ``K_a >= 0`` is added on top of it and
forgetting pulls ``K_a`` back to zero, i.e. ``K`` back to what the skill asked for; a skill thus
states the compliance it needs and adaptation only stiffens where errors persist. Adapted
``F_ff`` and ``K_a`` survive new commands (adaptation across a skill is the point) and are
cleared by :meth:`AdaptiveImpedance.reset`.

The law is written by hand: it is a handful of element-wise updates specific to this
controller, not something a library provides. This class is the reference and the law of the
real Franka's loop and of the simulated FR3; the floating tool runs the same adaptation compiled
(:func:`teachfit.control.compiled.adapt`, a test checks both agree). The FR3 keeps this one:
its trajectories would change in the last bits with the compiled one (numpy's matrix product
and :mod:`teachfit.core.geometry` against plain loops and MuJoCo's quaternion routines).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from teachfit.control.impedance import (
    DampingMemo,
    SetpointError,
    clip_wrench,
    clipped_twist,
)
from teachfit.core.control import (
    AdaptiveLimits,
    AdaptiveParams,
    ImpedanceLimits,
    MetaBounds,
    meta_bounds,
)
from teachfit.core.errors import ControlError
from teachfit.core.state import ImpedanceCommand

__all__ = ["AdaptiveImpedance", "AdaptiveLimits", "AdaptiveParams", "MetaBounds", "meta_bounds"]


class AdaptiveImpedance:
    """Adaptive Cartesian impedance controller; see the module docstring for the law.

    Implements :class:`~teachfit.control.base.Controller`.

    Parameters
    ----------
    apparent_mass : (6,) array
        Apparent mass / inertia per axis (kg, kg·m²), for damping from stiffness.
    params : AdaptiveParams
        Meta-parameters. ``alpha gamma_a < 1`` and ``beta gamma_b < 1`` are required (else the
        discrete forgetting overshoots and oscillates).
    limits : AdaptiveLimits
        Stiffness / feed-forward limits and rate limits of the adaptation.
    impedance_limits : ImpedanceLimits
        Output wrench and desired-speed limits, as for the fixed-gain controller.
    period : float
        Control period ``T`` (s); the controller advances one adaptation step per
        :meth:`compute` call, which a robot makes once per tick.
    damping_ratio : float or None
        ``xi`` for the adaptive damping term; ``None`` uses each command's ``damping_ratio``.
    """

    def __init__(
        self,
        apparent_mass: np.ndarray | Sequence[float],
        params: AdaptiveParams | None = None,
        limits: AdaptiveLimits | None = None,
        impedance_limits: ImpedanceLimits | None = None,
        period: float = 0.001,
        damping_ratio: float | None = None,
    ) -> None:
        m = np.asarray(apparent_mass, dtype=float).reshape(-1)
        if m.shape != (6,) or not np.all(m > 0):
            raise ControlError(f"apparent_mass must be 6 positive numbers, got {apparent_mass}")
        if not period > 0:
            raise ControlError(f"period must be > 0 s, got {period}")
        if damping_ratio is not None and not damping_ratio >= 0:
            raise ControlError(f"damping_ratio must be >= 0, got {damping_ratio}")
        self.mass = m
        self.params = params or AdaptiveParams()
        self.limits = limits or AdaptiveLimits()
        self.impedance_limits = impedance_limits or ImpedanceLimits()
        self.period = float(period)
        self.damping_ratio = damping_ratio
        p, lim = self.params, self.limits
        self._alpha = np.array(p.alpha)
        self._beta = np.array(p.beta)
        self._gamma_a = np.array(p.gamma_a)
        self._gamma_b = np.array(p.gamma_b)
        self._kappa = np.array(p.kappa)
        if np.any(self._alpha * self._gamma_a >= 1) or np.any(self._beta * self._gamma_b >= 1):
            raise ControlError("alpha*gamma_a and beta*gamma_b must be < 1 per coordinate")
        self._k_max = np.array(lim.k_max)
        self._k_max_list = np.broadcast_to(self._k_max, (6,)).tolist()
        self._dk_step = np.array(lim.dk_max) * self.period
        self._f_max = np.array(lim.f_max)
        self._df_step = np.array(lim.df_max) * self.period
        self._neg_f_max = -self._f_max
        self._neg_df_step = -self._df_step
        self._neg_dk_step = -self._dk_step
        self._sqrt_m2 = 2.0 * np.sqrt(m)
        # state and per-tick buffers, allocated once (compute() runs at 1 kHz)
        self._ff_adapt = np.zeros(6)
        self._k_adapt = np.zeros(6)
        self._k0 = np.zeros((6, 6))
        self._k0_diag = np.zeros(6)
        self._sqrt_k0 = np.zeros(6)
        self._k_room = np.zeros(6)
        self._d0 = np.zeros((6, 6))
        self._damping = DampingMemo(m)
        self._xi = 1.0
        self._error = SetpointError()
        self._fd = np.zeros(6)
        self._eps = np.zeros(6)
        self._step = np.zeros(6)
        self._tmp = np.zeros(6)
        self._has_cmd = False
        self.last_wrench = np.zeros(6)

    # ------------------------------------------------------------------------ inspection
    @property
    def feedforward(self) -> np.ndarray:
        """Adapted feed-forward wrench ``F_ff`` (6,) (N, N·m), a copy."""
        return self._ff_adapt.copy()

    @property
    def stiffness(self) -> np.ndarray:
        """Current diagonal stiffness ``K_cmd,ii + K_a`` (6,) (N/m, N·m/rad), a copy."""
        return self._k0_diag + self._k_adapt

    @property
    def stiffness_adapt(self) -> np.ndarray:
        """Adaptive stiffness ``K_a`` (6,) on top of the command's, a copy."""
        return self._k_adapt.copy()

    @property
    def damping(self) -> np.ndarray:
        """Current diagonal damping (6,) (N·s/m, N·m·s/rad)."""
        return np.diag(self._d0) + self._adaptive_damping(np.zeros(6))

    # ------------------------------------------------------------------ Controller protocol
    def reset(self) -> None:
        """Forget the adapted ``F_ff`` and ``K_a`` and the last command."""
        self._ff_adapt[:] = 0.0
        self._k_adapt[:] = 0.0
        self._has_cmd = False
        self.last_wrench = np.zeros(6)

    def set_command(self, cmd: ImpedanceCommand, t: float) -> None:
        """Adopt ``cmd`` at time ``t`` (s); its stiffness is the floor of the adapted one.

        Raises :class:`ControlError` if a diagonal stiffness exceeds ``k_max``.
        """
        diag = cmd.stiffness.diagonal()  # a read-only view: copied into _k0_diag below
        # per 10 ms command: a comparison of the lists costs a third of np.any's
        if any(k > m for k, m in zip(diag.tolist(), self._k_max_list, strict=True)):
            raise ControlError(
                f"command stiffness {diag.tolist()} exceeds k_max {self._k_max.tolist()}"
            )
        ilim = self.impedance_limits
        self._k0[:] = cmd.stiffness
        self._k0_diag[:] = diag
        np.sqrt(diag, out=self._sqrt_k0)
        np.subtract(self._k_max, diag, out=self._k_room)
        np.minimum(self._k_adapt, self._k_room, out=self._k_adapt)
        self._xi = cmd.damping_ratio if self.damping_ratio is None else self.damping_ratio
        if cmd.damping is None:
            self._d0[:] = self._damping(self._k0, cmd.damping_ratio)
        else:
            self._d0[:] = cmd.damping
        self._error.set(cmd, clipped_twist(cmd, ilim), t)
        self._fd[:] = cmd.wrench_ff
        self._has_cmd = True

    def _adaptive_damping(self, out: np.ndarray) -> np.ndarray:
        """``2 xi sqrt(m) (sqrt(K_cmd,ii + K_a) - sqrt(K_cmd,ii))`` into ``out`` (6,)."""
        np.add(self._k0_diag, self._k_adapt, out=out)
        np.sqrt(out, out=out)
        out -= self._sqrt_k0
        out *= self._sqrt_m2
        out *= self._xi
        return out

    def compute(
        self,
        t: float,
        pos: np.ndarray,
        quat: np.ndarray,
        lin_vel: np.ndarray,
        ang_vel: np.ndarray,
    ) -> np.ndarray:
        """Adapt once (one period ``T``) and return the wrench ``[f; tau]`` (6,), world, TCP.

        ``pos`` (3,), ``quat`` (4,) w-x-y-z, ``lin_vel`` and ``ang_vel`` (3,) in the world frame.
        """
        if not self._has_cmd:
            raise ControlError("compute() called before set_command()")
        # the same errors as CartesianImpedance (x_d extrapolated with the desired twist)
        err, derr = self._error.update(t, pos, quat, lin_vel, ang_vel)
        eps, step, tmp = self._eps, self._step, self._tmp
        # eps = de + kappa e
        np.multiply(self._kappa, err, out=eps)
        eps += derr
        # F_ff += clip(alpha (eps - gamma_a F_ff), +-dF_max T), then clip to +-F_max
        np.multiply(self._gamma_a, self._ff_adapt, out=step)
        np.subtract(eps, step, out=step)
        step *= self._alpha
        # (np.minimum/np.maximum: several times cheaper than np.clip at this size)
        np.minimum(step, self._df_step, out=step)
        np.maximum(step, self._neg_df_step, out=step)
        ff = self._ff_adapt
        ff += step
        np.minimum(ff, self._f_max, out=ff)
        np.maximum(ff, self._neg_f_max, out=ff)
        # K_a += clip(beta (eps e - gamma_b K_a), +-dK_max T), then clip to [0, K_max - K_cmd]
        np.multiply(self._gamma_b, self._k_adapt, out=step)
        np.multiply(eps, err, out=tmp)
        tmp -= step
        tmp *= self._beta
        np.minimum(tmp, self._dk_step, out=tmp)
        np.maximum(tmp, self._neg_dk_step, out=tmp)
        ka = self._k_adapt
        ka += tmp
        np.minimum(ka, self._k_room, out=ka)
        np.maximum(ka, 0.0, out=ka)
        # w = K e + D de + F_d + F_ff
        w = self._k0 @ err
        w += self._d0 @ derr
        np.multiply(self._k_adapt, err, out=tmp)
        w += tmp
        self._adaptive_damping(tmp)
        tmp *= derr
        w += tmp
        w += self._fd
        w += self._ff_adapt
        clip_wrench(w, self.impedance_limits)
        self.last_wrench = w
        return w
