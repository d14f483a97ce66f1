"""Plausibility checks: is an imported log something a search demonstration can be?

A log can be read without error and still be wrong: time stamps in ms read as s (a 0.02 Hz,
80-hour "demonstration"), a quaternion read in the wrong component order (unit norm, but the
tool tumbles), the wrench of the robot stored as the wrench of the environment, or several
minutes of several tasks in one file. Each check returns a :class:`Finding` naming the fix;
:func:`enforce` turns the findings that were not accepted into one clear error.

Checks (names for ``--accept``): ``rate`` and ``wrench_sign`` look at the whole log;
``orientation``, ``duration``, ``extent`` and ``speed`` at each demonstration cut from it (a long
log may turn the tool between its demonstrations). All quantities
are in the stored frame, which is assumed to have z up (the robot base or the world).
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass

import numpy as np

from teachfit.core.errors import DatasetError
from teachfit.core.geometry import wxyz_to_rotation
from teachfit.demonstrations.frames import QUAT_ORDERS, from_wxyz, to_wxyz
from teachfit.demonstrations.rawlog import RawLog, sampling_rate

CHECKS: tuple[str, ...] = ("rate", "orientation", "wrench_sign", "duration", "extent", "speed")
SCALES: tuple[tuple[float, str], ...] = ((1e-3, "ms"), (1e-6, "us"), (1e-9, "ns"), (1.0, "s"))


@dataclass(frozen=True)
class Limits:
    """What a search demonstration can be (SI units: Hz, s, m, m/s, rad, N)."""

    min_rate_hz: float = 5.0
    max_rate_hz: float = 10_000.0
    min_duration_s: float = 0.5
    max_duration_s: float = 120.0
    max_extent_m: float = 0.1
    min_speed_m_s: float = 1e-4
    max_speed_m_s: float = 0.5
    max_tilt_rad: float = math.radians(45.0)
    max_step_rad: float = math.radians(30.0)
    contact_force_n: float = 3.0
    min_contact_samples: int = 5


@dataclass(frozen=True)
class Finding:
    """One failed check: its name (for ``--accept``), what is wrong and how to fix it."""

    check: str
    message: str
    fix: str


def check_rate(log: RawLog, limits: Limits) -> Finding | None:
    """Sampling rate from the median time step."""
    rate = sampling_rate(log.t)
    if limits.min_rate_hz <= rate <= limits.max_rate_hz:
        return None
    message = (
        f"sampling rate {rate:.3g} Hz is outside {limits.min_rate_hz:g}..{limits.max_rate_hz:g} Hz"
    )
    if str(log.meta.get("source_format", "")).startswith("ros"):
        return Finding("rate", message, "check the header stamps of the pose topic")
    if log.time_step_units is None:
        return Finding("rate", message, "check the rate (" + log.hint("rate_hz", "<Hz>") + ")")
    for scale, unit in SCALES:
        fitted = 1.0 / (log.time_step_units * scale)
        if limits.min_rate_hz <= fitted <= limits.max_rate_hz:
            fix = (
                f"the time column steps by {log.time_step_units:g} units: if it is in {unit}, "
                + log.hint("time_scale", f"{scale:g}")
            )
            return Finding("rate", message, fix)
    return Finding("rate", message, "check the time column and " + log.hint("time_scale", "<s>"))


def _tilt(quat: np.ndarray) -> np.ndarray:
    """Angle (rad) between each tool z-axis and the first one."""
    axes = wxyz_to_rotation(quat).apply([0.0, 0.0, 1.0])
    return np.arccos(np.clip(axes @ axes[0], -1.0, 1.0))


def _steps(quat: np.ndarray) -> np.ndarray:
    """Rotation angle (rad) between consecutive orientations."""
    dots = np.abs(np.einsum("ij,ij->i", quat[1:], quat[:-1]))
    return 2.0 * np.arccos(np.clip(dots, 0.0, 1.0))


def _orientation_fault(quat: np.ndarray, limits: Limits) -> tuple[str, float, int] | None:
    """``("jump", deg, i)`` for a jump between samples i and i + 1, ``("tilt", deg, i)`` for
    a tool axis tilting beyond the limit (most at sample i), or None for a plausible track."""
    steps = _steps(quat)
    if steps.size and steps.max() > limits.max_step_rad:
        i = int(np.argmax(steps))
        return "jump", math.degrees(steps[i]), i
    tilt = _tilt(quat)
    if tilt.max() > limits.max_tilt_rad:
        i = int(np.argmax(tilt))
        return "tilt", math.degrees(tilt[i]), i
    return None


def _fault_text(fault: tuple[str, float, int]) -> str:
    kind, deg, _ = fault
    return f"jumps by {deg:.0f} deg" if kind == "jump" else f"tilts up to {deg:.0f} deg"


def _points_down(quat: np.ndarray) -> bool:
    """Whether the tool z-axis mostly points down (-z), as a searching tool does."""
    axes = wxyz_to_rotation(quat).apply([0.0, 0.0, 1.0])
    return bool(np.median(axes[:, 2]) < -0.5)


def _order_fix(log: RawLog, limits: Limits, kind: str) -> str:
    """The fix for an implausible orientation (``kind`` "jump" or "tilt" as read): the
    component order that fits, or why none does."""
    raw = from_wxyz(log.quat, log.quat_order)  # the components as read from the file
    others = {o: _orientation_fault(to_wxyz(raw, o), limits) for o in QUAT_ORDERS}
    others.pop(log.quat_order)
    fits = [o for o, fault in others.items() if fault is None]
    segment = "cut the log into demonstrations (--segment contact, window or marker)"
    if not fits:
        tried = "; ".join(f"read as {o} the tool {_fault_text(f)}" for o, f in others.items() if f)
        order = "quat_order" if log.fix_in is not None else "the quaternion fields"
        if kind == "jump":  # no tool turns that far in one sample
            return (
                f"no component order fits ({tried}): check the quaternion columns and {order} "
                "(a column swapped or missing part way, or samples of two sources interleaved)"
            )
        return (
            f"no component order fits ({tried}): if the tool really turns this much, {segment}; "
            f"else check the quaternion columns and {order}"
        )
    where = (
        log.hint("quat_order", f'"{fits[0]}"')
        if log.fix_in
        else "the bag's orientation fields are filled in another order: fix its publisher"
    )
    if _points_down(log.quat) and not _points_down(to_wxyz(raw, fits[0])):
        return (
            f"read as {fits[0]} the track would pass, but the tool would point up, while read as "
            f"{log.quat_order} it points down as a searching tool does: the tool probably really "
            f"turns, {segment}; if the order is wrong after all, {where}"
        )
    return f"the quaternion components are in {fits[0]} order (read so, the track fits): {where}"


def check_orientation(log: RawLog, limits: Limits) -> Finding | None:
    """The orientation track is continuous (no step over ``max_step_rad``) and the tool axis
    stays within ``max_tilt_rad`` of its first direction; run on each demonstration cut from a
    log. The fix names the quaternion component order that fits, if another does."""
    fault = _orientation_fault(log.quat, limits)
    if fault is None:
        return None
    kind, deg, i = fault
    if kind == "jump":
        message = (
            f"the orientation jumps by {deg:.0f} deg between {log.row_word} {log.rows[i]} and "
            f"{log.rows[i + 1]} (read as {log.quat_order}); a search turns the tool smoothly"
        )
    else:
        message = (
            f"the tool axis tilts up to {deg:.0f} deg from its first direction (at "
            f"{log.row_word[:-1]} {log.rows[i]}, read as {log.quat_order}); a search keeps it "
            f"within {math.degrees(limits.max_tilt_rad):.0f} deg"
        )
    return Finding("orientation", message, _order_fix(log, limits, kind))


def check_wrench_sign(log: RawLog, limits: Limits) -> Finding | None:
    """While pressing down in contact, the environment pushes the tool up (+z)."""
    if log.wrench is None:
        return None
    force = log.wrench[:, :3]
    norm = np.linalg.norm(force, axis=1)
    vertical = (norm > limits.contact_force_n) & (np.abs(force[:, 2]) >= 0.5 * norm)
    if np.count_nonzero(vertical) < limits.min_contact_samples:
        return None
    fz = float(np.median(force[vertical, 2]))
    if fz > 0:
        return None
    sign = int(log.meta.get("wrench_sign", 1))
    message = (
        f"in contact ({np.count_nonzero(vertical)} samples with |F| > "
        f"{limits.contact_force_n:g} N, mostly vertical) the force on the tool points down "
        f"(median fz = {fz:+.1f} N in {log.frame!r}); pressing down, the environment pushes the "
        "tool up (+z)"
    )
    what = (
        "the log holds the wrench the robot applies"
        if sign == 1
        else "the log already holds the wrench the environment exerts, and wrench_sign = -1 "
        "negates it"
    )
    fix = f"{what}: flip wrench_sign, " + log.hint("wrench_sign", -sign)
    return Finding("wrench_sign", message, fix)


def check_demo_shape(t: np.ndarray, pos: np.ndarray, log: RawLog, limits: Limits) -> list[Finding]:
    """Duration, x-y extent and speed of one demonstration (``t`` s, ``pos`` (T, 3) m)."""
    found = []
    duration = float(t[-1] - t[0])
    segment = "cut it into demonstrations (--segment contact, window or marker)"
    if duration > limits.max_duration_s:
        message = (
            f"{duration:.4g} s long; one search demonstration lasts at most "
            f"{limits.max_duration_s:g} s"
        )
        fix = f"if the time unit is right, {segment}"
        found.append(Finding("duration", message, fix))
    elif duration < limits.min_duration_s:
        message = f"only {duration:.3g} s long (a search lasts at least {limits.min_duration_s} s)"
        found.append(Finding("duration", message, "check time_scale / the rate"))
    extent = np.ptp(pos[:, :2], axis=0)
    if extent.max() > limits.max_extent_m:
        message = (
            f"the tool covers {extent[0] * 1e3:.0f} x {extent[1] * 1e3:.0f} mm in x-y; a search "
            f"stays within {limits.max_extent_m * 1e3:.0f} mm"
        )
        fix = f"check length_scale, or if the log holds several tasks or moves, {segment}"
        found.append(Finding("extent", message, fix))
    speeds = np.linalg.norm(np.diff(pos, axis=0), axis=1) / np.diff(t)
    top = float(np.percentile(speeds, 95))
    moving = speeds[speeds > 0.1 * top] if top > 0 else speeds
    speed = float(np.median(moving))
    if not limits.min_speed_m_s <= speed <= limits.max_speed_m_s:
        message = (
            f"the tool moves at {speed * 1e3:.3g} mm/s (median while moving), outside "
            f"{limits.min_speed_m_s * 1e3:g}..{limits.max_speed_m_s * 1e3:g} mm/s"
        )
        found.append(Finding("speed", message, "check time_scale and length_scale"))
    return found


def enforce(
    findings: list[Finding], accept: Collection[str], where: str, context: str = ""
) -> list[str]:
    """Raise for the first finding whose check is not in ``accept``; notes for the others.

    Raises
    ------
    DatasetError
        Naming ``where`` (the file), what is implausible and the fix.
    """
    unknown = sorted(set(accept) - {*CHECKS, "all"})
    if unknown:
        raise DatasetError(f"unknown check {unknown[0]!r} to accept (checks: {', '.join(CHECKS)})")
    refused = [f for f in findings if f.check not in accept and "all" not in accept]
    if refused:
        first = refused[0]
        more = sorted({f.check for f in refused[1:]} - {first.check})
        raise DatasetError(
            f"{context}implausible {first.check}: {first.message}. Fix: {first.fix}"
            + (f" (also implausible: {', '.join(more)})" if more else "")
            + f". If the log really is like this, pass --accept {first.check}"
            " (or --accept-implausible).",
            path=where,
        )
    return [f"{context}accepted implausible {f.check}: {f.message}" for f in findings]
