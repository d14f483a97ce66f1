"""Demonstrations -> search states and (step, action wrench) pairs, in the search frame.

The *search state* ``s`` of a demonstration sample is its pose relative to the first pose of
that demonstration, restricted to the search degrees of freedom of the task (its
``search_dims``, :func:`teachfit.tasks.registry.search_dims_of`), e.g.:

* ``peg2d``, ``peg``:   ``s = (x, y)``                 (m)
* ``socket3d``, ``puzzle``, ``key``: ``s = (x, y, rz)``  (m, m, rad; ``rz`` about z, unwrapped)

The *action* is the wrench the teacher applied, i.e. minus the wrench the environment exerted on
the tool, restricted to the same DOFs: ``a = -(fx, fy)`` (N) or ``a = -(fx, fy, tz)`` (N, N m).
Steps are ``Δs_t = s_{t+1} - s_t`` at a common sample rate (demonstrations are linearly
resampled to it first), so that a model can convert a trajectory's velocity into steps.

Inputs are :class:`teachfit.demonstrations.dataset.Demonstration` objects or anything with the
attributes ``t``, ``pos``, ``quat`` (w, x, y, z) and ``wrench`` (e.g. :class:`DemoArrays`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from teachfit.core.errors import ModelError, TaskError
from teachfit.core.geometry import rotation_to_wxyz, rz_from_quat, wxyz_to_rotation
from teachfit.tasks.registry import search_dims_of

_WRENCH_INDEX = {"x": 0, "y": 1, "z": 2, "rx": 3, "ry": 4, "rz": 5}
_POS_INDEX = {"x": 0, "y": 1, "z": 2}


def dims_for_task(task: str) -> tuple[str, ...]:
    """Search DOFs of the built-in task ``task`` (its ``search_dims``); ModelError if unknown."""
    try:
        return search_dims_of(task)
    except TaskError as exc:
        raise ModelError(str(exc)) from None


def validate_dims(dims: Sequence[str]) -> tuple[str, ...]:
    """Check a tuple of search DOF names (``x``, ``y``, ``z``, ``rz``), each at most once."""
    dims = tuple(dims)
    if not dims or len(set(dims)) != len(dims):
        raise ModelError(f"dims must be non-empty and unique, got {dims!r}")
    bad = [d for d in dims if d not in ("x", "y", "z", "rz")]
    if bad:
        raise ModelError(f"unsupported search dims {bad!r}; use x, y, z, rz")
    return dims


@dataclass(frozen=True)
class DemoArrays:
    """Plain-array stand-in for a Demonstration (same fields, same units and frames).

    ``t`` (T,) s; ``pos`` (T, 3) m; ``quat`` (T, 4) w, x, y, z; ``wrench`` (T, 6) N, N m exerted
    by the environment on the tool, or None.
    """

    t: np.ndarray
    pos: np.ndarray
    quat: np.ndarray
    wrench: np.ndarray | None = None
    name: str = ""


@dataclass(frozen=True)
class SearchData:
    """Search states and (Δs, a) pairs of one or more demonstrations, resampled to ``rate_hz``.

    Attributes
    ----------
    dims : tuple of str
        Search DOFs, length D.
    states : ndarray, shape (N, D)
        All search states of all demonstrations (search frame; m, rad).
    steps : ndarray, shape (M, D)
        ``Δs_t = s_{t+1} - s_t`` within each demonstration (never across two).
    actions : ndarray, shape (M, D) or None
        Action wrench ``-wrench`` on the search DOFs at the same samples as ``steps``; None when
        no demonstration carries a wrench.
    rate_hz : float
        Common sample rate of ``steps``.
    speed : float
        Median translational speed in the search plane while moving, m/s.
    angular_speed : float or None
        Median |d rz/dt| while rotating, rad/s (None when ``rz`` is not a search DOF).
    n_demos : int
        Number of demonstrations.
    """

    dims: tuple[str, ...]
    states: np.ndarray
    steps: np.ndarray
    actions: np.ndarray | None
    rate_hz: float
    speed: float
    angular_speed: float | None
    n_demos: int


def yaw_relative(quat: np.ndarray) -> np.ndarray:
    """Unwrapped rotation about z of each orientation relative to the first one.

    With ``q_rel = q_0^{-1} ⊗ q_t`` (scipy, through the geometry kernel), ``rz`` is the z-y-x
    yaw of ``q_rel`` (:func:`~teachfit.core.geometry.rz_from_quat`). ``quat`` is (T, 4)
    (w, x, y, z; normalised here); returns (T,) rad, unwrapped, ``rz[0] = 0``.
    """
    q = np.asarray(quat, dtype=float)
    rot = wxyz_to_rotation(q / np.linalg.norm(q, axis=1, keepdims=True))
    yaw = rz_from_quat(rotation_to_wxyz(rot[0].inv() * rot))
    return np.unwrap(yaw - yaw[0])


def _demo_arrays(
    demo: Any, dims: tuple[str, ...]
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """(t, states, actions) of one demonstration at its own samples.

    The search frame is the recording frame translated to the first pose, its axes kept (seed
    A), and rz is relative to the first yaw: exactly how :mod:`teachfit.execution.search` maps
    search states back from a new start, so fixture-fixed directions stay fixed.
    """
    t = np.asarray(demo.t, dtype=float)
    pos = np.asarray(demo.pos, dtype=float)
    quat = np.asarray(demo.quat, dtype=float)
    name = getattr(demo, "name", "") or "<demo>"
    if t.ndim != 1 or t.size < 2 or pos.shape != (t.size, 3) or quat.shape != (t.size, 4):
        raise ModelError(f"{name}: need t (T,), pos (T,3), quat (T,4) with T >= 2")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(pos)) and np.all(np.isfinite(quat))):
        raise ModelError(f"{name}: NaN or inf in t, pos or quat")
    if np.any(np.diff(t) <= 0):
        raise ModelError(f"{name}: time stamps must increase strictly")
    cols = []
    for d in dims:
        if d == "rz":
            cols.append(yaw_relative(quat))
        else:
            cols.append(pos[:, _POS_INDEX[d]] - pos[0, _POS_INDEX[d]])
    states = np.stack(cols, axis=1)
    actions = None
    if getattr(demo, "wrench", None) is not None:
        wrench = np.asarray(demo.wrench, dtype=float)
        if wrench.shape != (t.size, 6) or not np.all(np.isfinite(wrench)):
            raise ModelError(f"{name}: wrench must be finite with shape (T, 6)")
        actions = -wrench[:, [_WRENCH_INDEX[d] for d in dims]]
    return t, states, actions


def _resample(t: np.ndarray, values: np.ndarray, rate_hz: float) -> np.ndarray:
    grid = t[0] + np.arange(int(np.floor((t[-1] - t[0]) * rate_hz + 1e-9)) + 1) / rate_hz
    return np.stack([np.interp(grid, t, v) for v in values.T], axis=1)


def _moving_median(speeds: np.ndarray) -> float:
    """Median speed over the samples that move (speed > 10 % of the 95th percentile)."""
    if speeds.size == 0:
        return 0.0
    top = np.percentile(speeds, 95)
    moving = speeds[speeds > 0.1 * top] if top > 0 else speeds
    return float(np.median(moving)) if moving.size else 0.0


def search_data(
    demos: Iterable[Any], dims: Sequence[str], *, rate_hz: float | None = None
) -> SearchData:
    """Search states and (Δs, a) pairs of demonstrations, in each demonstration's search frame.

    Parameters
    ----------
    demos : iterable of Demonstration or DemoArrays
        One or more demonstrations. Positions are taken relative to the first sample in the
        recording frame's axes, rz relative to the first yaw.
    dims : sequence of str
        Search DOFs, e.g. ``("x", "y")`` or ``("x", "y", "rz")``.
    rate_hz : float, optional
        Common sample rate; default: the median of the demonstrations' median sample rates.

    Raises
    ------
    ModelError
        No demonstrations, malformed arrays, NaN, or non-increasing time stamps.
    """
    dims = validate_dims(dims)
    if isinstance(demos, DemoArrays) or hasattr(demos, "pos"):
        demos = [demos]
    raw = [_demo_arrays(d, dims) for d in demos]
    if not raw:
        raise ModelError("no demonstrations given")
    if rate_hz is None:
        rate_hz = float(np.median([1.0 / np.median(np.diff(t)) for t, _, _ in raw]))
    if not (np.isfinite(rate_hz) and rate_hz > 0):
        raise ModelError(f"rate_hz must be positive, got {rate_hz}")
    states, steps, actions = [], [], []
    has_wrench = all(a is not None for _, _, a in raw)
    for t, s, a in raw:
        rs = _resample(t, s, rate_hz)
        states.append(rs)
        steps.append(np.diff(rs, axis=0))
        if has_wrench and a is not None:  # a is never None when has_wrench
            actions.append(_resample(t, a, rate_hz)[:-1])
    steps_all = np.concatenate(steps)
    lin = [i for i, d in enumerate(dims) if d != "rz"]
    speed = _moving_median(np.linalg.norm(steps_all[:, lin], axis=1) * rate_hz)
    ang = None
    if "rz" in dims:
        ang = _moving_median(np.abs(steps_all[:, dims.index("rz")]) * rate_hz)
    return SearchData(
        dims=dims,
        states=np.concatenate(states),
        steps=steps_all,
        actions=np.concatenate(actions) if has_wrench else None,
        rate_hz=float(rate_hz),
        speed=speed,
        angular_speed=ang,
        n_demos=len(raw),
    )
