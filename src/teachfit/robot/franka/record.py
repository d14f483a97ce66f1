"""Kinesthetic teaching: record a demonstration while a person guides the compliant arm.

Works with any :class:`~teachfit.robot.interface.Robot` (the Franka driver, or the simulated
floating tool in tests). The robot is reset *where it is* with fixed-gain impedance (which also
zeroes the wrench reading, so tare before anyone touches the arm), then runs a zero-stiffness
law: gravity compensated (the firmware's), light damping only, and nothing pulls the TCP
anywhere. Samples are taken every ``1 / rate_hz`` s until ``duration`` runs out or Ctrl-C.
A robot with ``tap(every)`` / ``untap()`` (the Franka driver) samples in its own control
thread, so no sample is lost when the calling thread runs late; others are sampled by the
caller after each ``step``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from teachfit.core.control import FixedGainSpec
from teachfit.core.errors import ControlError, RobotFault
from teachfit.core.state import ImpedanceCommand, RobotState
from teachfit.robot.interface import Robot

#: light damping of the guided arm (N·s/m, N·m·s/rad)
GUIDING_DAMPING = (10.0, 10.0, 10.0, 0.3, 0.3, 0.3)


@dataclass(frozen=True)
class KinestheticRecording:
    """A recorded demonstration (world frame at the TCP).

    ``t`` (N,) s since the recording started, ``pos`` (N, 3) m, ``quat`` (N, 4) w-x-y-z,
    ``wrench`` (N, 6) N and N·m the environment exerts on the tool (what the person and
    contacts push with), ``interrupted`` whether Ctrl-C ended it, ``fault`` the message of the
    robot fault that ended it ("" if none).
    """

    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    wrench: np.ndarray
    interrupted: bool = False
    fault: str = ""

    def __len__(self) -> int:
        return int(self.t.shape[0])


def _pack(
    samples: list[RobotState], t0: float, interrupted: bool, fault: str
) -> KinestheticRecording:
    if not samples:
        return KinestheticRecording(
            np.zeros(0), np.zeros((0, 3)), np.zeros((0, 4)), np.zeros((0, 6)), interrupted, fault
        )
    return KinestheticRecording(
        t=np.array([s.t for s in samples]) - t0,
        pos=np.array([s.pos for s in samples]),
        quat=np.array([s.quat for s in samples]),
        wrench=np.array([s.wrench for s in samples]),
        interrupted=interrupted,
        fault=fault,
    )


@runtime_checkable
class _Tapping(Protocol):
    """A robot that samples its state in its control thread (the Franka driver)."""

    def tap(self, every: int) -> None: ...
    def untap(self) -> list[RobotState]: ...


def record_kinesthetic(
    robot: Robot,
    duration: float | None = None,
    rate_hz: float = 100.0,
    damping: tuple[float, ...] = GUIDING_DAMPING,
) -> KinestheticRecording:
    """Record the guided arm for ``duration`` s (``None``: until Ctrl-C) at ``rate_hz``.

    Ctrl-C (``KeyboardInterrupt``) ends the recording and keeps every sample
    (``interrupted=True``). A :class:`~teachfit.core.errors.RobotFault` ends it too: the fault
    is re-raised with the recording attached as its ``recording`` attribute.
    """
    if not rate_hz > 0:
        raise ControlError(f"rate_hz must be > 0, got {rate_hz}")
    if duration is not None and not duration > 0:
        raise ControlError(f"duration must be > 0 s or None, got {duration}")
    every = max(1, int(round(1.0 / (rate_hz * robot.control_period))))
    start = robot.reset(robot.state().pose, FixedGainSpec())
    robot.command(
        ImpedanceCommand(
            pos=start.pos,
            quat=start.quat,
            stiffness=np.zeros(6),  # none: the person guides the arm
            damping=np.asarray(damping, dtype=float),
            expires_after=1e9,
        )
    )
    tapper = robot if isinstance(robot, _Tapping) else None
    samples: list[RobotState] = [start]
    if tapper is not None:
        tapper.tap(every)
    try:
        last = start
        while duration is None or last.t - start.t < duration:
            last = robot.step(every)
            if tapper is None:
                samples.append(last)
    except KeyboardInterrupt:
        return _pack(_collect(tapper, samples), start.t, True, "")
    except RobotFault as fault:
        rec = _pack(_collect(tapper, samples), start.t, False, str(fault))
        fault.recording = rec  # type: ignore[attr-defined]  # attached for the caller
        raise
    samples = _collect(tapper, samples)
    robot.command(ImpedanceCommand.hold(samples[-1].pose))  # stay where the person left it
    return _pack(samples, start.t, False, "")


def _collect(tapper: _Tapping | None, samples: list[RobotState]) -> list[RobotState]:
    if tapper is not None:
        samples += [s for s in tapper.untap() if s.t > samples[0].t]
    return samples
