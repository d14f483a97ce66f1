"""Structural types of the pylibfranka objects the torque tick reads (pylibfranka ships no
type information): a ``RobotState`` packet and the robot ``Model``.

Vectors are libfranka's plain sequences: 4x4 transforms as 16 column-major values (m),
joint values (7,) in rad, rad/s or N·m, wrenches (6,) in N and N·m.
"""

from __future__ import annotations

from typing import Protocol

import numpy.typing as npt


class LibfrankaState(Protocol):
    """The fields of ``pylibfranka.RobotState`` that teachfit reads."""

    @property
    def O_T_EE(self) -> npt.ArrayLike: ...  # noqa: N802 - libfranka's name
    @property
    def EE_T_K(self) -> npt.ArrayLike: ...  # noqa: N802 - libfranka's name
    @property
    def O_F_ext_hat_K(self) -> npt.ArrayLike: ...  # noqa: N802 - libfranka's name
    @property
    def q(self) -> npt.ArrayLike: ...
    @property
    def dq(self) -> npt.ArrayLike: ...


class LibfrankaModel(Protocol):
    """The methods of ``pylibfranka.Model`` that teachfit calls."""

    def zero_jacobian(self, state: LibfrankaState) -> npt.ArrayLike:
        """The EE frame's zero Jacobian (6x7, column-major, base frame)."""
        ...

    def coriolis(self, state: LibfrankaState) -> npt.ArrayLike:
        """Coriolis torques (7,) N·m."""
        ...
