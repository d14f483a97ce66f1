"""The blind teacher's hand: the path it intends, its noise and its press.

Every function draws from the generator it is given, in a fixed order, so a seeded teacher
plans the same path on every machine. Lengths in m, times in s, forces in N.
"""

from __future__ import annotations

import numpy as np

from teachfit.core.geometry import Pose, quat_from_rz
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.teacher_style import TeacherStyle
from teachfit.tasks.base import Task


def hand_plan(
    task: Task,
    st: TeacherStyle,
    rng: np.random.Generator,
    press_rng: np.random.Generator,
    start: Pose,
) -> SetpointTrajectory:
    """The path the teacher's hand intends from ``start``, world frame, for ``max_duration``:
    towards its belief of the hole (the true hole plus ``belief_sigma`` noise) and on in its
    pattern, with the hand's noise, the yaw wiggle where the task searches in rz, and the
    press's wander (drawn from ``press_rng``, apart from the other draws)."""
    dt = 1.0 / st.record_rate
    n = int(st.max_duration / dt) + 1
    hole = task.hole2world.pos[:2]
    belief = hole + rng.normal(0.0, st.belief_sigma, 2)
    p0 = start.pos[:2]
    if st.pattern == "sweep":
        n_app = min(n - 1, max(2, int(2.0 / dt)))  # turn towards the belief in 2 s
        xy = sweep(st, rng, p0, belief, n, dt)
    else:
        approach_len = float(np.linalg.norm(belief - p0))
        n_app = min(max(2, int(approach_len / st.speed / dt)), n - 1)
        lam = np.linspace(0.0, 1.0, n_app)[:, None]
        approach = p0 + lam * (belief - p0)
        xy = np.concatenate([approach, belief + search_pattern(st, rng, n - n_app, dt)])[:n]
    xy = xy + hand_noise(st, rng, n, dt)
    xy[0] = p0
    t = dt * np.arange(n)
    if "rz" in task.search_dims:
        period = float(getattr(task, "rz_period", 2 * np.pi))
        rz0 = start.rz
        target = task.hole2world.rz
        target += period * np.round((rz0 - target) / period)
        target += rng.normal(0.0, st.rz_belief_sigma)
        rz = np.empty(n)
        rz[:n_app] = rz0 + np.linspace(0.0, 1.0, n_app) * (target - rz0)
        tt = t[n_app:] - t[n_app]
        rz[n_app:] = target + st.rz_wiggle * np.sin(2 * np.pi * st.rz_wiggle_frequency * tt)
        quat = quat_from_rz(rz)
    else:
        quat = np.tile(start.quat, (n, 1))
    pos = np.column_stack([xy, np.full(n, task.surface_z)])
    ff = np.zeros((n, 6))
    ff[:, 2] = -press_wander(st, n, dt, press_rng)  # on the follow skill's constant push
    return SetpointTrajectory.from_path(t, pos, quat, wrench_ff=ff, name="teacher-plan")


def search_pattern(st: TeacherStyle, rng: np.random.Generator, n: int, dt: float) -> np.ndarray:
    """(n, 2) offsets around the belief, at the teacher's speed (``"spiral"`` or
    ``"zigzag"``), m."""
    s = st.speed * dt * np.arange(n)  # arc length
    if st.pattern == "spiral":
        # Archimedean spiral r = b theta, arc length ~ b theta^2 / 2
        b = st.spiral_pitch / (2 * np.pi)
        theta = np.sqrt(2 * s / b)
        theta += rng.uniform(0, 2 * np.pi)
        r = b * (theta - theta[0])
        return np.column_stack([r * np.cos(theta), r * np.sin(theta)])
    # zig-zag raster: rows spiral_pitch apart, growing width
    width = 0.008
    row_len = width + st.spiral_pitch
    row = np.floor(s / row_len)
    u = s - row * row_len
    x = np.where(row % 2 == 0, u, row_len - u) - width / 2
    y = row * st.spiral_pitch - width / 2
    return np.column_stack([np.clip(x, -width / 2, width / 2), y])


def sweep(
    st: TeacherStyle,
    rng: np.random.Generator,
    p0: np.ndarray,
    belief: np.ndarray,
    n: int,
    dt: float,
) -> np.ndarray:
    """(n, 2) raster from ``p0`` across the direction to ``belief`` and past it, world, m."""
    span = float(np.linalg.norm(belief - p0))
    u = (belief - p0) / span if span > 1e-9 else np.array([1.0, 0.0])
    v = np.array([-u[1], u[0]]) * rng.choice([-1.0, 1.0])
    w, pitch = st.sweep_halfwidth, st.spiral_pitch
    rows = int(np.ceil((span + w) / pitch)) + 1
    corners = [np.zeros(2)]
    side = 1.0
    for k in range(rows):
        corners += [np.array([k * pitch, side * w]), np.array([(k + 1) * pitch, side * w])]
        side = -side
    local = _along_polyline(np.array(corners), st.speed * dt * np.arange(n))
    return p0 + local[:, :1] * u + local[:, 1:] * v


def hand_noise(st: TeacherStyle, rng: np.random.Generator, n: int, dt: float) -> np.ndarray:
    """(n, 2) slow wander (Ornstein-Uhlenbeck) plus tremor, low-passed over
    ``hand_smoothing`` s when positive, m."""
    a = np.exp(-dt / st.wander_timescale)
    sd = st.wander_amplitude * np.sqrt(1 - a * a)
    w = np.zeros((n, 2))
    kicks = rng.normal(0.0, sd, (n, 2))
    for i in range(1, n):
        w[i] = a * w[i - 1] + kicks[i]
    phase = rng.uniform(0, 2 * np.pi, 2)
    t = dt * np.arange(n)
    tremor = st.tremor_amplitude * np.sin(2 * np.pi * st.tremor_frequency * t[:, None] + phase)
    if st.hand_smoothing > 0:  # the same draws through a hand of lower bandwidth
        # imported here: scipy.signal (and the scipy.stats it loads) is 0.5-1 s of every
        # command's start-up, and only a smoothed hand needs it
        from scipy.signal import lfilter

        c = np.exp(-dt / st.hand_smoothing)
        return lfilter([1.0 - c], [1.0, -c], w + tremor, axis=0)
    return w + tremor


def press_wander(style: TeacherStyle, n: int, dt: float, rng: np.random.Generator) -> np.ndarray:
    """(n,) a teacher's press deviation from ``style.push_force`` every ``dt`` s (N, positive
    presses harder).

    An assumption, not a measurement we can cite for kinesthetic teaching: a person holding a
    steady push of a few newtons drifts by a few percent of it, slowly (force-steadiness
    studies report coefficients of variation of a few percent at low forces, most of the
    fluctuation's power below 1-2 Hz). Modelled as a stationary Ornstein-Uhlenbeck process of
    standard deviation ``style.press_wander`` and time constant ``style.press_timescale``.
    """
    a = np.exp(-dt / style.press_timescale)
    kicks = rng.normal(0.0, style.press_wander * np.sqrt(1 - a * a), n)
    dev = np.empty(n)
    dev[0] = rng.normal(0.0, style.press_wander)  # started stationary
    for i in range(1, n):
        dev[i] = a * dev[i - 1] + kicks[i]
    return dev


def _along_polyline(corners: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points at arc lengths ``s`` along the polyline through ``corners`` (clamped at its end)."""
    seg = np.linalg.norm(np.diff(corners, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    return np.column_stack([np.interp(s, cum, corners[:, j]) for j in range(corners.shape[1])])
