"""The percept primitives and conditions see, and the command a primitive emits.

Everything is expressed in the skill's *task frame* ``task2world`` (for peg-in-hole the
estimated hole frame: origin at the estimated hole entry, z out of the surface). With
``R = R(task2world)`` and ``o`` its origin, a world TCP position ``x`` is ``p = R^T (x - o)`` in
the task frame; twists and wrenches rotate with ``R^T``. Both objects are allocated once per
execution and updated in place every command tick.
"""

from __future__ import annotations

import math

import numpy as np

from teachfit.core.geometry import Pose, quat_conj_into, quat_mul_into, quat_to_matrix_into
from teachfit.core.state import RobotState


class Percept:
    """What the robot knows at one command tick, task frame unless stated.

    Attributes
    ----------
    t, t_node : s since the skill / the active node started.
    dt : s, the command period.
    p, v, w : (3,) TCP position (m), linear (m/s) and angular (rad/s) velocity.
    q : (4,) TCP orientation relative to the task frame (w, x, y, z).
    f : (6,) wrench ``[f; tau]`` the environment exerts on the tool (N, N·m).
    p_d, q_d : (3,), (4,) the commanded set-point (m; w-x-y-z), task frame.
    goal : (3,) where the active primitive is heading (NaN when it has no goal).
    done : whether the active primitive finished its own motion (e.g. its profile).
    detected : whether the task's success detector holds for the measured pose (``False``
        when the execution has no detector).
    pos, quat : (3,), (4,) TCP pose in the world (m; w-x-y-z).
    shared : per-execution state the nodes of one graph share, by name (e.g. ``"tilt"``:
        a tilted search's :class:`~teachfit.skills.tilt_context.TiltContext`).
    """

    def __init__(self, task2world: Pose, dt: float) -> None:
        self.task2world = task2world
        self.rot = task2world.rotation.as_matrix()  # task -> world (3, 3)
        self.rot_t = self.rot.T.copy()
        self.origin = np.array(task2world.pos)
        self.q_task = np.array(task2world.quat)
        self._q_task_inv = np.zeros(4)
        quat_conj_into(self._q_task_inv, self.q_task)
        self.dt = float(dt)
        self.t = 0.0
        self.t_node = 0.0
        self.pos = np.zeros(3)
        self.quat = np.array([1.0, 0.0, 0.0, 0.0])
        self.p = np.zeros(3)
        self.v = np.zeros(3)
        self.w = np.zeros(3)
        self.q = np.array([1.0, 0.0, 0.0, 0.0])
        self.f = np.zeros(6)
        self.p_d = np.zeros(3)
        self.q_d = np.array([1.0, 0.0, 0.0, 0.0])
        self.goal = np.full(3, np.nan)
        self.done = False
        self.detected = False
        self.shared: dict[str, object] = {}
        self._tmp = np.zeros(3)
        self._mat = np.zeros(9)

    def update(self, state: RobotState, t: float) -> None:
        """Adopt a measured state at skill time ``t`` (s)."""
        self.t = t
        rt = self.rot_t
        self.pos[:] = state.pos
        self.quat[:] = state.quat
        np.subtract(state.pos, self.origin, out=self._tmp)
        np.dot(rt, self._tmp, out=self.p)
        np.dot(rt, state.lin_vel, out=self.v)
        np.dot(rt, state.ang_vel, out=self.w)
        np.dot(rt, state.wrench[:3], out=self.f[:3])
        np.dot(rt, state.wrench[3:], out=self.f[3:])
        quat_mul_into(self.q, self._q_task_inv, state.quat)

    def hold_here(self, position_only: bool = False) -> None:
        """Set the set-point to the measured pose (a primitive starting from where it is);
        ``position_only``: the commanded orientation is kept."""
        self.p_d[:] = self.p
        if not position_only:
            self.q_d[:] = self.q

    # ------------------------------------------------------------------ derived values
    @property
    def depth(self) -> float:
        """How far the TCP is below the task frame's x-y plane (m, positive inside)."""
        return -float(self.p[2])

    @property
    def lateral(self) -> float:
        """Distance of the TCP from the task frame's z-axis (m)."""
        return math.hypot(self.p[0], self.p[1])

    @property
    def remaining(self) -> float:
        """Distance of the TCP from the active primitive's goal (m; NaN without one)."""
        g = self.goal
        p = self.p
        return math.sqrt((p[0] - g[0]) ** 2 + (p[1] - g[1]) ** 2 + (p[2] - g[2]) ** 2)

    @property
    def tilt(self) -> float:
        """Angle between the tool's z-axis and the task frame's z-axis (rad)."""
        quat_to_matrix_into(self._mat, self.q)
        cz = float(self._mat[8])  # z-component of the tool z-axis
        return math.acos(min(1.0, max(-1.0, cz)))

    def to_world_pose(self, p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A task-frame pose as world ``(pos (3,), quat (4,))``."""
        pos = np.dot(self.rot, p)  # the product ``@`` makes, with less dispatch
        pos += self.origin
        quat = np.zeros(4)
        quat_mul_into(quat, self.q_task, q)
        return pos, quat


class MPCommand:
    """What a primitive emits each command tick, task frame (Johannsmeier et al. 2019, Sec. III).

    ``twist`` (6,) desired ``[v; w]`` (m/s, rad/s) that moves the set-point over the next
    command period, ``wrench`` (6,) feed-forward ``[f; tau]`` (N, N·m) the robot adds,
    ``stiffness`` (6,) diagonal Cartesian stiffness (N/m, N·m/rad) along the task axes, or,
    with ``full`` set, ``stiffness_full`` (6, 6) (e.g. stiff along a search path and compliant
    across it). A primitive that sets the set-point itself writes ``pc.p_d``/``pc.q_d``.
    """

    __slots__ = ("twist", "wrench", "stiffness", "stiffness_full", "full")

    def __init__(self) -> None:
        self.twist = np.zeros(6)
        self.wrench = np.zeros(6)
        self.stiffness = np.zeros(6)
        self.stiffness_full = np.zeros((6, 6))
        self.full = False

    def clear(self) -> None:
        self.twist[:] = 0.0
        self.wrench[:] = 0.0
        self.full = False
