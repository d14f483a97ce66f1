"""The controller role: turn an impedance command and the measured motion into a wrench."""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from teachfit.core.state import ImpedanceCommand


@runtime_checkable
class Controller(Protocol):
    """A Cartesian controller called once per control tick (1 kHz in simulation).

    Implementations: :class:`~teachfit.control.impedance.CartesianImpedance` (fixed gains) and
    the adaptive impedance controller. Any skill or search runs on either.
    """

    def reset(self) -> None:
        """Forget any state (adapted gains, last command)."""
        ...

    def set_command(self, cmd: ImpedanceCommand, t: float) -> None:
        """Adopt a new set-point at time ``t`` (s)."""
        ...

    def compute(
        self,
        t: float,
        pos: np.ndarray,
        quat: np.ndarray,
        lin_vel: np.ndarray,
        ang_vel: np.ndarray,
    ) -> np.ndarray:
        """The wrench ``[f; tau]`` (6,) to apply at the TCP, world frame (N, N·m)."""
        ...
