"""Time-sampled set-point trajectories: what the runner executes.

A :class:`SetpointTrajectory` holds desired TCP poses and feed-forward wrenches at sample
times, in the world frame. Search trajectories (planned in a search frame), replayed
demonstrations and skills all become one before execution.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from teachfit.core.errors import ControlError
from teachfit.core.geometry import Pose, rotation_to_wxyz, wxyz_to_rotation


@dataclass(frozen=True)
class SetpointTrajectory:
    """Desired TCP motion, world frame.

    Attributes
    ----------
    t : (T,) s, strictly increasing, starting at 0.
    pos : (T, 3) m.
    quat : (T, 4) w-x-y-z.
    wrench_ff : (T, 6) feed-forward wrench [f; tau] (N, N·m) added by the controller.
    name : label for logs and figures.
    """

    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    wrench_ff: np.ndarray
    name: str = ""
    meta: dict[str, float | str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        t = np.array(self.t, dtype=float).reshape(-1)
        n = t.size
        pos = np.array(self.pos, dtype=float).reshape(n, 3) if n else np.zeros((0, 3))
        quat = np.array(self.quat, dtype=float).reshape(n, 4) if n else np.zeros((0, 4))
        ff = np.array(self.wrench_ff, dtype=float).reshape(n, 6) if n else np.zeros((0, 6))
        if n < 2:
            raise ControlError(f"a trajectory needs at least 2 samples, got {n}")
        for name, arr in (("t", t), ("pos", pos), ("quat", quat), ("wrench_ff", ff)):
            if not np.all(np.isfinite(arr)):
                raise ControlError(f"trajectory {name} contains NaN or inf")
        if np.any(np.diff(t) <= 0):
            raise ControlError("trajectory times must be strictly increasing")
        quat = quat / np.linalg.norm(quat, axis=1, keepdims=True)
        for arr in (t, pos, quat, ff):
            arr.setflags(write=False)
        object.__setattr__(self, "t", t - t[0])
        object.__setattr__(self, "pos", pos)
        object.__setattr__(self, "quat", quat)
        object.__setattr__(self, "wrench_ff", ff)

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    @property
    def path_length(self) -> float:
        return float(np.linalg.norm(np.diff(self.pos, axis=0), axis=1).sum())

    def sample(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Set-point at time ``t`` (held at the ends): ``pos, quat, lin_vel, wrench_ff``.

        Positions and wrenches are interpolated linearly; the orientation is taken from the
        nearest earlier sample (trajectories here change orientation slowly and densely).
        """
        ts = self.t
        i = int(np.clip(np.searchsorted(ts, t, side="right") - 1, 0, ts.size - 2))
        dt = ts[i + 1] - ts[i]
        a = float(np.clip((t - ts[i]) / dt, 0.0, 1.0))
        pos = (1 - a) * self.pos[i] + a * self.pos[i + 1]
        vel = (self.pos[i + 1] - self.pos[i]) / dt if 0.0 <= t < ts[-1] else np.zeros(3)
        ff = (1 - a) * self.wrench_ff[i] + a * self.wrench_ff[i + 1]
        quat = self.quat[i + 1] if a > 0.5 else self.quat[i]
        return pos, quat, vel, ff

    @classmethod
    def from_path(
        cls,
        t: np.ndarray,
        pos: np.ndarray,
        quat: np.ndarray | None = None,
        wrench_ff: np.ndarray | None = None,
        name: str = "",
    ) -> SetpointTrajectory:
        n = len(t)
        q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)) if quat is None else quat
        ff = np.zeros((n, 6)) if wrench_ff is None else wrench_ff
        return cls(t=t, pos=pos, quat=q, wrench_ff=ff, name=name)

    def transformed(self, frame2world: Pose) -> SetpointTrajectory:
        """The trajectory given in ``frame`` mapped into the world: poses and wrenches."""
        rot = frame2world.rotation
        pos = rot.apply(np.array(self.pos)) + frame2world.pos
        quat = rotation_to_wxyz(rot * wxyz_to_rotation(self.quat))
        ff = np.concatenate(
            [
                rot.apply(np.array(self.wrench_ff[:, :3])),
                rot.apply(np.array(self.wrench_ff[:, 3:])),
            ],
            axis=1,
        )
        return SetpointTrajectory(self.t, pos, quat, ff, self.name, dict(self.meta))
