"""Safety limits of the Franka driver: checked before anything is sent and on every tick.

All Cartesian quantities are in the task's world frame at the TCP (m, m/s, rad/s, N, N·m);
joint torques in N·m. The firmware has its own, stricter-when-set reflexes
(``set_collision_behavior``); these limits are the driver's: they end the control loop with a
:class:`~teachfit.core.errors.LimitViolation` (measured motion) or refuse a command before it is
sent (commanded wrench, set-point outside the workspace).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from teachfit.core.errors import ControlError, LimitViolation
from teachfit.core.state import ImpedanceCommand

Vec3 = tuple[float, float, float]
Vec7 = tuple[float, float, float, float, float, float, float]

#: FR3/Panda joint torque limits (N·m), as in libfranka's robot documentation
FRANKA_TORQUE_LIMITS: Vec7 = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)


@dataclass(frozen=True)
class FrankaLimits:
    """The driver's limits.

    Parameters
    ----------
    max_tcp_speed, max_tcp_ang_speed : measured TCP speed (m/s, rad/s) that faults the loop.
    max_force, max_torque : largest commanded wrench (N, N·m): a command whose feed-forward is
        larger is refused; the control law's output is scaled down to it every tick.
    workspace_lo, workspace_hi : corners of the box (m, world frame) the TCP and every
        commanded set-point must stay in.
    workspace_margin : how far (m) the *measured* TCP may leave the box before the loop faults.
    max_torque_rate : joint torque rate (N·m/s) the sent torques are limited to (libfranka's
        ``kMaxTorqueRate``, 1000 N·m/s).
    joint_torque_limits : per-joint torque magnitude (N·m) the sent torques are clipped to.
    reset_speed, reset_ang_speed : speed (m/s, rad/s) of the set-point during :meth:`reset`.
    """

    max_tcp_speed: float = 0.5
    max_tcp_ang_speed: float = 2.0
    max_force: float = 60.0
    max_torque: float = 6.0
    workspace_lo: Vec3 = (-0.3, -0.3, -0.02)
    workspace_hi: Vec3 = (0.3, 0.3, 0.45)
    workspace_margin: float = 0.02
    max_torque_rate: float = 1000.0
    joint_torque_limits: Vec7 = FRANKA_TORQUE_LIMITS
    reset_speed: float = 0.05
    reset_ang_speed: float = 0.3

    def __post_init__(self) -> None:
        for name in (
            "max_tcp_speed",
            "max_tcp_ang_speed",
            "max_force",
            "max_torque",
            "max_torque_rate",
            "reset_speed",
            "reset_ang_speed",
        ):
            if not getattr(self, name) > 0:
                raise ControlError(f"{name} must be > 0, got {getattr(self, name)}")
        lo, hi = np.asarray(self.workspace_lo, float), np.asarray(self.workspace_hi, float)
        if lo.shape != (3,) or hi.shape != (3,) or not np.all(lo < hi):
            raise ControlError(f"workspace box needs lo < hi (3 each), got {lo}, {hi}")
        if not self.workspace_margin >= 0:
            raise ControlError("workspace_margin must be >= 0")
        if len(self.joint_torque_limits) != 7 or min(self.joint_torque_limits) <= 0:
            raise ControlError("joint_torque_limits needs 7 positive values")

    def rows(self) -> list[tuple[str, str]]:
        """``(limit, value with unit)`` rows for ``teachfit robot check``."""
        lo, hi = self.workspace_lo, self.workspace_hi
        box = " x ".join(f"[{a:+.3f}, {b:+.3f}]" for a, b in zip(lo, hi, strict=True))
        return [
            ("max TCP speed", f"{self.max_tcp_speed:g} m/s, {self.max_tcp_ang_speed:g} rad/s"),
            ("max commanded wrench", f"{self.max_force:g} N, {self.max_torque:g} N·m"),
            ("workspace box (world)", f"{box} m, margin {self.workspace_margin:g} m"),
            ("torque rate limit", f"{self.max_torque_rate:g} N·m/s"),
            ("joint torque limits", ", ".join(f"{v:g}" for v in self.joint_torque_limits)),
            ("reset speed", f"{self.reset_speed:g} m/s, {self.reset_ang_speed:g} rad/s"),
        ]

    # ------------------------------------------------------------------ checks
    def in_workspace(self, pos: np.ndarray, margin: float = 0.0) -> bool:
        """Whether ``pos`` (3,) (m, world) lies in the box grown by ``margin`` (m)."""
        lo = np.asarray(self.workspace_lo) - margin
        hi = np.asarray(self.workspace_hi) + margin
        return bool(np.all(pos >= lo) and np.all(pos <= hi))

    def check_target(self, pos: np.ndarray, what: str) -> None:
        """Raise :class:`LimitViolation` if the set-point ``pos`` is outside the workspace."""
        if not self.in_workspace(np.asarray(pos, float)):
            raise LimitViolation(
                f"{what} {np.round(pos, 4).tolist()} m is outside the workspace box "
                f"{self.workspace_lo} .. {self.workspace_hi} m (world frame)"
            )

    def check_command(self, cmd: ImpedanceCommand) -> None:
        """Refuse ``cmd`` (:class:`LimitViolation`) before it reaches the control loop."""
        f = float(np.linalg.norm(cmd.wrench_ff[:3]))
        t = float(np.linalg.norm(cmd.wrench_ff[3:]))
        if f > self.max_force or t > self.max_torque:
            raise LimitViolation(
                f"commanded feed-forward wrench {f:.1f} N / {t:.2f} N·m exceeds the limit "
                f"{self.max_force:g} N / {self.max_torque:g} N·m; nothing was sent"
            )
        self.check_target(cmd.pos, "commanded set-point")

    def check_motion(self, pos: np.ndarray, lin_vel: np.ndarray, ang_vel: np.ndarray) -> str:
        """Why the measured TCP motion breaks a limit ("" when it does not); per tick."""
        v = float(np.sqrt(lin_vel @ lin_vel))
        if v > self.max_tcp_speed:
            return f"TCP speed {v:.3f} m/s over the limit {self.max_tcp_speed:g} m/s"
        w = float(np.sqrt(ang_vel @ ang_vel))
        if w > self.max_tcp_ang_speed:
            return f"TCP angular speed {w:.3f} rad/s over the limit {self.max_tcp_ang_speed:g}"
        if not self.in_workspace(pos, self.workspace_margin):
            return f"TCP {np.round(pos, 4).tolist()} m left the workspace box"
        return ""
