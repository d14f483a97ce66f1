"""The one execution log: what the engine records at ``log_rate`` for every kind of run."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from teachfit.core.state import RobotState


@dataclass(frozen=True)
class ExecutionLog:
    """Measured and commanded signals (world frame at the TCP unless stated).

    Attributes
    ----------
    t : (T,) s since the execution started.
    pos : (T, 3) m;  quat : (T, 4) w-x-y-z;  wrench : (T, 6) N, N·m exerted by the environment.
    setpoint_pos : (T, 3) m, the last commanded set-point;  setpoint_quat : (T, 4) w-x-y-z, its
    orientation.
    wrench_ff : (T, 6) N, N·m, the last commanded feed-forward wrench.
    depth : (T,) m below the task frame's x-y plane.
    node : (T,) index of the active node (-1: recovery).
    """

    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    wrench: np.ndarray
    setpoint_pos: np.ndarray
    wrench_ff: np.ndarray
    depth: np.ndarray
    node: np.ndarray
    setpoint_quat: np.ndarray

    @property
    def n_samples(self) -> int:
        return int(self.t.size)


class LogBuffer:
    """Preallocated rows for :class:`ExecutionLog` (the loop allocates nothing to log)."""

    def __init__(self, n: int) -> None:
        self.t, self.depth = np.zeros(n), np.zeros(n)
        self.pos, self.quat, self.wrench = np.zeros((n, 3)), np.zeros((n, 4)), np.zeros((n, 6))
        self.setpoint_pos, self.wrench_ff = np.zeros((n, 3)), np.zeros((n, 6))
        self.setpoint_quat = np.zeros((n, 4))
        self.node = np.zeros(n, dtype=int)
        self.k = 0

    def add(
        self,
        t: float,
        state: RobotState,
        depth: float,
        setpoint_pos: np.ndarray,
        wrench_ff: np.ndarray,
        node: int,
        setpoint_quat: np.ndarray,
    ) -> None:
        k = self.k
        if k < self.t.size:
            self.t[k], self.depth[k], self.node[k] = t, depth, node
            self.pos[k], self.quat[k], self.wrench[k] = state.pos, state.quat, state.wrench
            self.setpoint_pos[k], self.wrench_ff[k] = setpoint_pos, wrench_ff
            self.setpoint_quat[k] = setpoint_quat
            self.k = k + 1

    def freeze(self) -> ExecutionLog:
        k = self.k
        return ExecutionLog(
            self.t[:k].copy(),
            self.pos[:k].copy(),
            self.quat[:k].copy(),
            self.wrench[:k].copy(),
            self.setpoint_pos[:k].copy(),
            self.wrench_ff[:k].copy(),
            self.depth[:k].copy(),
            self.node[:k].copy(),
            self.setpoint_quat[:k].copy(),
        )
