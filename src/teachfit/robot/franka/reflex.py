"""The firmware's collision reflex the driver sets on connect (``setCollisionBehavior``).

A Franka's firmware stops the arm (``cartesian_reflex`` / ``joint_reflex``) when its external
wrench estimate passes the *upper* collision thresholds; over the *lower* ones it only flags
contact. libfranka's own examples set 20 N per Cartesian axis, which a contact skill exceeds
in normal work: the peg skill's lateral move presses the part against the hole's edge with
17-19 N along the move (measured on the protocol twin), and its insertion force is learned up
to 20 N. A contact application sets the thresholds *above what its controller may exert*, so
the reflex stays the backstop for what goes really wrong (an impact at speed, a jam the
driver's own checks miss), and the driver's checks (a skill's ``f_max``, the reset's
``abort_force``, :class:`~teachfit.robot.franka.safety.FrankaLimits`) act first.

The thresholds (:func:`reflex_thresholds`), per Cartesian axis of the wrench at the stiffness
frame ``K`` and per joint:

* **force** (N): ``reflex_force``, by default :data:`REFLEX_MARGIN` times the largest force the
  control law may command (``FrankaLimits.max_force``, 60 N: 75 N). A skill's force limit
  (the peg skill's ``f_max`` 50 N) and the reset's abort force (15 N) are below it.
* **torque** (N·m): the margin times ``max_torque`` plus ``reflex_force`` at the lever from
  ``K`` to the TCP (the TCP's force seen at ``K``).
* **joints** (N·m): the joint torques that wrench at the TCP causes at the pose where the
  driver connects (``reflex_force`` times the column norm of the TCP Jacobian's linear part,
  plus the torque times its angular part), never below libfranka's defaults (the joint
  estimate reads a few N·m of model error at rest) nor above the joint torque limits.

The lower (contact) thresholds are libfranka's defaults, or the upper ones where those are
lower. Both are sent as the nominal and the acceleration-phase thresholds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from teachfit.core.errors import ControlError
from teachfit.robot.franka.safety import FrankaLimits

#: factor over the largest wrench the control law may command
REFLEX_MARGIN = 1.25
#: libfranka's example thresholds (``setDefaultBehavior``): per joint (N·m), Cartesian (N, N·m)
LIBFRANKA_JOINT = (20.0, 20.0, 18.0, 18.0, 16.0, 14.0, 12.0)
LIBFRANKA_CARTESIAN = (20.0, 20.0, 20.0, 25.0, 25.0, 25.0)


@dataclass(frozen=True)
class ReflexThresholds:
    """``setCollisionBehavior``'s arguments: per joint (7,) (N·m) and per Cartesian axis at
    ``K`` (6,) (N, N·m), contact (lower) and collision (upper)."""

    lower_torque: tuple[float, ...]
    upper_torque: tuple[float, ...]
    lower_force: tuple[float, ...]
    upper_force: tuple[float, ...]

    def send(self, robot: Any) -> None:
        """``robot.set_collision_behavior(...)`` (a pylibfranka ``Robot``, idle)."""
        robot.set_collision_behavior(
            list(self.lower_torque),
            list(self.upper_torque),
            list(self.lower_force),
            list(self.upper_force),
        )

    def describe(self) -> str:
        """One line: the upper thresholds with units."""
        f, t = self.upper_force[0], self.upper_force[3]
        joints = ", ".join(f"{v:.0f}" for v in self.upper_torque)
        return f"{f:g} N, {t:.2f} N·m at K; joints {joints} N·m"


def check_reflex_force(value: float, what: str = "reflex_force") -> float:
    """``value`` (N) if it is a finite force > 0; :class:`ControlError` naming ``what`` else."""
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise ControlError(
            f"{what} {value}: give the collision reflex's force threshold in N, a number > 0 "
            f"(default {REFLEX_MARGIN:g} x the driver's force limit)"
        )
    return float(value)


def reflex_thresholds(
    limits: FrankaLimits,
    jacobian: np.ndarray,
    k_lever: float,
    reflex_force: float | None = None,
) -> ReflexThresholds:
    """The thresholds (see the module docstring) for the TCP Jacobian ``jacobian`` (6, 7)
    (base frame, at the TCP) at the pose where the driver connects, ``k_lever`` (m) from ``K``
    to the TCP and ``reflex_force`` (N; ``None``: the margin over ``limits.max_force``)."""
    if reflex_force is None:
        force = REFLEX_MARGIN * limits.max_force
    else:
        force = check_reflex_force(reflex_force)
    torque_tcp = REFLEX_MARGIN * limits.max_torque
    torque_k = torque_tcp + force * float(k_lever)
    jac = np.asarray(jacobian, dtype=float)
    joint = force * np.linalg.norm(jac[:3], axis=0) + torque_tcp * np.linalg.norm(jac[3:], axis=0)
    joint = np.minimum(np.maximum(joint, LIBFRANKA_JOINT), limits.joint_torque_limits)
    upper_force = (force,) * 3 + (torque_k,) * 3
    return ReflexThresholds(
        lower_torque=tuple(float(v) for v in np.minimum(LIBFRANKA_JOINT, joint)),
        upper_torque=tuple(float(v) for v in joint),
        lower_force=tuple(float(v) for v in np.minimum(LIBFRANKA_CARTESIAN, upper_force)),
        upper_force=tuple(float(v) for v in upper_force),
    )
