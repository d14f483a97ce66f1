"""Temporal filtering of the relative pose: an alpha-beta (constant-velocity) filter on SE(3)
with innovation gating.

State: position ``p`` (m) and its rate ``v``, rotation ``R`` and its rate ``w`` (rad/s, left).
With ``dt`` the time since the last accepted frame and a measurement ``(p_m, R_m)``:

    prediction   p^ = p + v dt,            R^ = exp([w dt]) R
    innovation   e_p = p_m - p^,           e_R = log(R_m R^T)
    gate         reject when |e_p| > gate_mm + a_max dt^2 / 2 or |e_R| > gate_deg + b_max dt^2 / 2
                 (the frame is marked invalid; a_max, b_max bound a hand's accelerations)
    update       p = p^ + alpha e_p,       R = exp([alpha e_R]) R^
                 v = v + beta e_p / dt,    w = w + beta e_R / dt

A constant-velocity motion is followed without lag. With ``accel`` set, the gains adapt to
each measurement's predicted error ``sigma`` (m, rad) through Kalata's tracking index
``lam = accel * dt^2 / sigma``: ``r = (4 + lam - sqrt(8 lam + lam^2)) / 4``,
``alpha = 1 - r^2``, ``beta = 2 (2 - alpha) - 4 sqrt(1 - alpha)`` (the steady-state
Kalman gains of a constant-velocity model driven by white acceleration noise of standard
deviation ``accel``): precise measurements pass almost unchanged, noisy ones are smoothed.
After ``reacquire`` consecutive rejections
(or a gap longer than ``max_gap_s``) the filter restarts from the measurement: the rejected
frames stay marked, nothing is interpolated into them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.core.errors import CaptureError

__all__ = ["FilterConfig", "PoseFilter", "adaptive_alpha"]


def adaptive_alpha(accel: float, dt: float, sigma: float) -> float:
    """The adaptive position gain (Kalata's steady state): the weight a measurement with
    predicted error ``sigma`` (m) gets ``dt`` s after the last one, for hand accelerations of
    ``accel`` (m/s^2). Near 1 when ``sigma`` is far below ``accel dt^2``."""
    lam = accel * dt * dt / max(sigma, 1e-12)
    r = (4.0 + lam - np.sqrt(8.0 * lam + lam * lam)) / 4.0
    return float(1.0 - r * r)


@dataclass(frozen=True)
class FilterConfig:
    """Gains and gates of :class:`PoseFilter`.

    ``accel`` (m/s^2) and ``ang_accel`` (rad/s^2) are the hand's acceleration noise used for
    adaptive gains when measurement errors are given; otherwise (or when ``accel`` is None)
    the fixed ``alpha`` in (0, 1] and ``beta`` in [0, 1) apply; ``alpha = 1, beta = 0`` passes
    measurements through (gating still applies)."""

    alpha: float = 0.7
    beta: float = 0.15
    accel: float | None = 2.0
    ang_accel: float = 20.0
    gate_mm: float = 10.0
    gate_deg: float = 10.0
    gate_accel: float = 10.0
    gate_ang_accel: float = 100.0
    reacquire: int = 3
    max_gap_s: float = 0.5

    def __post_init__(self) -> None:
        if not (0 < self.alpha <= 1 and 0 <= self.beta < 1):
            raise CaptureError("filter alpha must be in (0, 1] and beta in [0, 1)")
        if self.accel is not None and not (self.accel > 0 and self.ang_accel > 0):
            raise CaptureError("filter accel and ang_accel must be > 0")
        if min(self.gate_accel, self.gate_ang_accel) < 0:
            raise CaptureError("filter gate accelerations must be >= 0")
        if self.gate_mm <= 0 or self.gate_deg <= 0 or self.reacquire < 1 or self.max_gap_s <= 0:
            raise CaptureError("filter gates, reacquire and max_gap_s must be > 0")


class PoseFilter:
    """Causal filter of (4, 4) poses; :meth:`update` returns the filtered pose or None."""

    def __init__(self, cfg: FilterConfig | None = None) -> None:
        self.cfg = cfg or FilterConfig()
        self._t: float | None = None
        self._rejects = 0

    def _reset(self, t: float, T: np.ndarray) -> np.ndarray:
        self._t, self._p, self._R = t, T[:3, 3].copy(), T[:3, :3].copy()
        self._v, self._w, self._rejects = np.zeros(3), np.zeros(3), 0
        return T.copy()

    def _gains(self, dt: float, sigma: float | None, accel: float) -> tuple[float, float]:
        if self.cfg.accel is None or sigma is None:
            return self.cfg.alpha, self.cfg.beta
        alpha = adaptive_alpha(accel, dt, sigma)
        return alpha, 2.0 * (2.0 - alpha) - 4.0 * np.sqrt(1.0 - alpha)

    def update(
        self,
        t: float,
        T: np.ndarray | None,
        sigma_m: float | None = None,
        sigma_rad: float | None = None,
    ) -> np.ndarray | None:
        """Feed the measurement at time ``t`` (s; None when the frame has none), optionally with
        its predicted 1-sigma errors in position (m) and rotation (rad)."""
        if T is None:
            return None
        if self._t is None or t - self._t > self.cfg.max_gap_s:
            return self._reset(t, T)
        dt = t - self._t
        if dt <= 0:
            raise CaptureError(f"filter times must increase, got {self._t} then {t}")
        p_hat = self._p + self._v * dt
        R_hat = Rotation.from_rotvec(self._w * dt).as_matrix() @ self._R
        e_p = T[:3, 3] - p_hat
        e_R = Rotation.from_matrix(T[:3, :3] @ R_hat.T).as_rotvec()
        cfg = self.cfg
        gate_mm = cfg.gate_mm + 1e3 * cfg.gate_accel * dt * dt / 2
        gate_deg = cfg.gate_deg + np.degrees(cfg.gate_ang_accel * dt * dt / 2)
        if 1e3 * np.linalg.norm(e_p) > gate_mm or np.degrees(np.linalg.norm(e_R)) > gate_deg:
            self._rejects += 1
            return self._reset(t, T) if self._rejects >= cfg.reacquire else None
        self._rejects = 0
        a_p, b_p = self._gains(dt, sigma_m, cfg.accel or 0.0)
        a_r, b_r = self._gains(dt, sigma_rad, cfg.ang_accel)
        self._p = p_hat + a_p * e_p
        self._R = Rotation.from_rotvec(a_r * e_R).as_matrix() @ R_hat
        self._v = self._v + b_p * e_p / dt
        self._w = self._w + b_r * e_R / dt
        self._t = t
        out = np.eye(4)
        out[:3, :3], out[:3, 3] = self._R, self._p
        return out
