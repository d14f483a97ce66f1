"""Scripted "human" demonstrations of the pose sequence ``L2G`` for the planning tasks.

The script follows the human strategy of the paper (Fig. 3) for the L: tilt, enter the opening
-x end first until the end touches under the lip, pivot down about that contact while sliding
under the lip, then translate home. For the tenon: swing the bar level in front of the near
mortise, then push it through both holes. On top of the nominal script, a seeded tremor
(low-pass filtered noise, ~0.3 mm and ~0.3 deg) and, occasionally, a short deliberate push
into contact reproduce the slight penetrations that captured demonstrations show.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import butter, sosfiltfilt
from scipy.spatial.transform import Rotation

from teachfit.core.errors import TaskError
from teachfit.core.geometry import rotation_to_wxyz
from teachfit.demonstrations.dataset import Demonstration
from teachfit.plans.collision import CollisionChecker
from teachfit.tasks.parts import Assembly

__all__ = ["nominal_keyframes", "synth_demo", "keyframes_to_poses"]


def _xyz_rpy(T: np.ndarray) -> np.ndarray:
    rpy = Rotation.from_matrix(T[:3, :3]).as_euler("xyz", degrees=True)
    return np.concatenate([T[:3, 3], rpy])


def _l_groove_keyframes(asm: Assembly) -> np.ndarray:
    d = asm.dimensions
    t, o = d["base_thickness"], d["opening_length"]
    lc, depth, lip = d["cavity_length"], d["cavity_depth"], d["lip_thickness"]
    x0 = lc / 2 - o  # lip edge
    top = depth + lip
    gap = 0.0015  # distance kept from floor, lip and end wall in the script (m)
    tilt0 = np.degrees(np.arctan((t + lip + 0.006) / (o - 0.004))) + 4.0

    def under_lip(phi_deg: float) -> float:
        """How far (m) the -x end may reach under the lip at tilt phi, end resting on the floor."""
        phi = np.radians(phi_deg)
        room = depth - gap - t / np.cos(phi) - gap
        reach = room / np.tan(phi) if phi > 1e-6 else np.inf
        return float(min(reach, x0 + lc / 2 - gap - t * np.sin(phi)))

    frames: list[np.ndarray | list[float]] = [_xyz_rpy(asm.start)]
    u0 = under_lip(tilt0)
    direction = np.array([np.cos(np.radians(tilt0)), np.sin(np.radians(tilt0))])
    above = np.array([x0 - u0, gap]) + 0.04 * direction
    frames.append([above[0], 0.0, max(above[1], top + 0.005), 0.0, -tilt0, 0.0])
    frames.append([above[0], 0.0, above[1], 0.0, -tilt0, 0.0])
    frames.append([x0 - u0, 0.0, gap, 0.0, -tilt0, 0.0])
    for phi in np.linspace(tilt0, 0.0, 13)[1:]:
        frames.append([x0 - under_lip(phi), 0.0, gap, 0.0, -phi, 0.0])
    frames.append(_xyz_rpy(asm.goal))
    return np.asarray(frames, dtype=float)


def _tenon_keyframes(asm: Assembly) -> np.ndarray:
    d = asm.dimensions
    near = 2 * d["mortise_thickness"] + d["mortise_gap"]
    zc = d["hole_height"]
    goal = _xyz_rpy(asm.goal)
    frames = [
        _xyz_rpy(asm.start),
        [near + 0.05, 0.0, zc + 0.03, 0.0, -20.0, 12.0],
        [near + 0.015, 0.0, zc, 0.0, 0.0, 0.0],
        [near - d["mortise_thickness"] / 2, 0.0, zc, 0.0, 0.0, 0.0],
        [near - d["mortise_thickness"] - d["mortise_gap"] / 2, 0.0, zc, 0.0, 0.0, 0.0],
        [d["mortise_thickness"] / 2, 0.0, zc, 0.0, 0.0, 0.0],
        goal,
    ]
    return np.asarray(frames, dtype=float)


def nominal_keyframes(asm: Assembly) -> np.ndarray:
    """(K, 6) scripted key frames ``[x, y, z (m), roll, pitch, yaw (deg)]`` of ``L2G``.

    The first is ``asm.start`` and the last ``asm.goal``; the straight interpolation between
    them is collision-free for the default parts.
    """
    if asm.task == "l-groove":
        return _l_groove_keyframes(asm)
    if asm.task == "tenon":
        return _tenon_keyframes(asm)
    raise TaskError(f"no demonstration script for task {asm.task!r}")


def keyframes_to_poses(
    frames: np.ndarray, rate_hz: float, speed: float = 0.03
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Interpolate key frames with a smooth stop at each one, as a person moving step by step.

    Parameters
    ----------
    frames : np.ndarray
        (K, 6) ``[x, y, z (m), roll, pitch, yaw (deg)]``.
    rate_hz : float
        Sample rate (Hz).
    speed : float
        Nominal speed (m/s; 1 deg counts as 1 mm) of each step.

    Returns
    -------
    t : (T,) s; pos : (T, 3) m; rpy : (T, 3) deg.
    """
    steps = []
    for a, b in zip(frames[:-1], frames[1:], strict=True):
        length = np.linalg.norm(b[:3] - a[:3]) + 1e-3 * np.linalg.norm(b[3:] - a[3:])
        n = max(int(np.ceil(length / speed * rate_hz)), 3)
        s = np.linspace(0.0, 1.0, n, endpoint=False)
        s = s * s * (3.0 - 2.0 * s)  # smoothstep: zero velocity at both key frames
        steps.append(a + s[:, None] * (b - a))
    steps.append(frames[-1:])
    path = np.concatenate(steps)
    t = np.arange(len(path)) / rate_hz
    return t, path[:, :3], path[:, 3:]


def synth_demo(
    asm: Assembly,
    seed: int,
    *,
    rate_hz: float = 30.0,
    tremor_mm: float = 0.3,
    tremor_deg: float = 0.3,
    p_penetrate: float = 0.5,
) -> Demonstration:
    """A synthetic human demonstration of ``L2G`` for ``asm``'s task.

    Parameters
    ----------
    asm : Assembly
        The task (its start and goal are the demonstration's ends, up to tremor).
    seed : int
        Seed of the tremor and of the deliberate contact.
    rate_hz : float
        Sampling rate (Hz) of the capture.
    tremor_mm, tremor_deg : float
        Standard deviation of the tremor in position (mm) and angle (deg); each is capped so
        that twice it moves the part's farthest point at most half the clearance.
    p_penetrate : float
        Probability that the demonstration contains a short push into contact.

    Returns
    -------
    Demonstration
        ``frame="G"``, ``child_frame="L"``, ``source="synthetic"``, no wrench; ``meta`` holds
        the seed, the number of colliding samples, whether the deliberate push happened and
        the tremors used.
    """
    if rate_hz <= 0 or tremor_mm < 0 or tremor_deg < 0 or not 0 <= p_penetrate <= 1:
        raise TaskError("rate_hz must be > 0, tremors >= 0 and p_penetrate in [0, 1]")
    rng = np.random.default_rng(seed)
    tremor_mm, tremor_deg = _steady_tremors(asm, tremor_mm, tremor_deg)
    t, pos, rpy = keyframes_to_poses(nominal_keyframes(asm), rate_hz)
    pos, rpy = _add_tremor(rng, pos, rpy, rate_hz, tremor_mm, tremor_deg)
    pushed = _maybe_push(rng, pos, p_penetrate, float(asm.dimensions["clearance"]))
    quat = rotation_to_wxyz(Rotation.from_euler("xyz", rpy, degrees=True))  # w >= 0
    colliding = _n_colliding(asm, pos, quat)
    return Demonstration(
        t=t,
        pos=pos,
        quat=quat,
        wrench=None,
        task=asm.task,
        source="synthetic",
        frame="G",
        child_frame="L",
        name=f"{asm.task}-synth-{seed}",
        meta={
            "seed": int(seed),
            "n_colliding": int(colliding),
            "pushed": bool(pushed),
            "tremor_mm": float(tremor_mm),
            "tremor_deg": float(tremor_deg),
            "generator": "teachfit.plans",
        },
    )


def _n_colliding(asm: Assembly, pos: np.ndarray, quat: np.ndarray) -> int:
    """How many poses (positions (T, 3) m, quaternions (T, 4) w-x-y-z) collide."""
    checker = CollisionChecker.of(asm)
    return sum(checker.collides_xyzq(*p, *q) for p, q in zip(pos, quat, strict=True))


def _steady_tremors(asm: Assembly, tremor_mm: float, tremor_deg: float) -> tuple[float, float]:
    """The tremors (mm, deg) capped for a steady hand, which keeps its tremor within the fit:
    2 sigma of either tremor moves the part's farthest point at most half the clearance, so
    tight variants get collision-free scripts."""
    room = 0.25 * float(asm.dimensions["clearance"])
    radius = float(np.linalg.norm(asm.moving.vertices, axis=1).max())
    return min(tremor_mm, 1e3 * room), min(tremor_deg, float(np.degrees(room / radius)))


def _add_tremor(
    rng: np.random.Generator,
    pos: np.ndarray,
    rpy: np.ndarray,
    rate_hz: float,
    tremor_mm: float,
    tremor_deg: float,
) -> tuple[np.ndarray, np.ndarray]:
    """``pos`` (T, 3) m and ``rpy`` (T, 3) deg plus a tremor: white noise low-passed at 2 Hz
    (physiological tremor and slow drift of a hand), tapered to zero at both ends."""
    n = len(pos)
    sos = butter(2, min(2.0 / (rate_hz / 2), 0.99), output="sos")
    noise = sosfiltfilt(sos, rng.standard_normal((n, 6)), axis=0, padlen=min(n - 1, 12))
    noise /= np.maximum(noise.std(axis=0, keepdims=True), 1e-12)
    taper = np.minimum(1.0, np.minimum(np.arange(n), np.arange(n)[::-1]) / 5.0)[:, None]
    return pos + 1e-3 * tremor_mm * noise[:, :3] * taper, rpy + tremor_deg * noise[:, 3:] * taper


def _maybe_push(
    rng: np.random.Generator, pos: np.ndarray, p_penetrate: float, clearance: float
) -> bool:
    """With probability ``p_penetrate``, a short push sideways into the fixed part, a typical
    capture artefact: moves a few samples of ``pos`` (T, 3) m in place by the clearance (m)
    plus 0.8 mm along y. Whether it happened."""
    if not rng.random() < p_penetrate:
        return False
    n = len(pos)
    i0 = int(rng.integers(n // 3, max(n // 3 + 1, n - 8)))
    span = slice(i0, min(i0 + 4, n - 1))
    pos[span, 1] += rng.choice([-1.0, 1.0]) * (clearance + 0.0008)
    return True
