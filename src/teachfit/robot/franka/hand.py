"""A scripted hand for the Franka twin: a person guiding the arm, as a force profile.

A *guide* is a CSV file with the header ``t,x,y,press`` and one row per waypoint: ``t`` the
time (s, strictly increasing), ``x``, ``y`` where the hand wants the held part's tip (the TCP)
in the task's hole frame (m), ``press`` the hand's downward push (N; negative lifts). Rows with
``t < 0`` are the lead-in: the hand brings the arm to where the demonstration starts before
anything is recorded; ``demo record --hand`` records from ``t = 0`` to the last row.

The hand is a person's, not a servo: it pulls the TCP towards the (linearly interpolated)
target with a spring-damper (:class:`HandParams`: 2500 N/m, 100 N·s/m on the speed relative to
the target's, capped at 15 N: stiff enough that the joints' and the surface's friction under a
6 N press leave it about 1 mm short at rest, inside a chamfered hole's capture), pushes down
with ``press`` while damping vertical motion as a hand does (``press_damping``), and holds the
tool upright (a rotational spring-damper to the orientation it found). The twin applies it as
an external force inside the physics (:class:`teachfit.robot.franka.twin_hand.TwinHand`), so
libfranka's ``O_F_ext_hat_K`` sees it as it would see a person's push: in free air the
recording reads the hand's vertical force, ``fz = -press - press_damping * vz`` (the
environment's force on the tool; ``-press`` where the hand holds still); pressed on the
fixture, the fixture's reaction cancels it in the joint-torque estimate, as on a real arm
(no wrist sensor). After the last row the hand lets go.

:func:`sweep_guide` draws a blind search like the simulated teacher's sweep
(:mod:`teachfit.execution.teacher_motion`): a raster of passes across the direction from the
start to the hole, ``pitch`` apart, advancing towards the hole, the last pass ending over it.
``python -m teachfit.robot.franka.hand OUT.csv [--start DX DY] [--seed N] [--press N]`` writes
one (hole frame: the same file serves any task).
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teachfit.core.atomic import atomic_write_text
from teachfit.core.errors import TeachfitError

HEADER = ("t", "x", "y", "press")
#: what a guide may hold: a file, rows, a target's reach from the hole (m), a press (N), s
MAX_BYTES = 4_000_000
MAX_ROWS = 100_000
MAX_REACH = 0.1
MAX_PRESS = 30.0
MAX_DURATION = 600.0
FIX = "give a CSV with the header t,x,y,press (s, m in the hole frame, N)"


class GuideError(TeachfitError):
    """A scripted hand's guide that cannot be used (the message names the file and the fix)."""


@dataclass(frozen=True)
class HandParams:
    """The hand's spring-damper: ``stiffness`` N/m and ``damping`` N·s/m across (x, y),
    ``max_force`` N its cap; ``press_damping`` N·s/m on vertical speed; ``rot_stiffness``
    N·m/rad, ``rot_damping`` N·m·s/rad and ``max_torque`` N·m holding the tool upright."""

    stiffness: float = 2500.0
    damping: float = 100.0
    max_force: float = 15.0
    press_damping: float = 40.0
    rot_stiffness: float = 10.0
    rot_damping: float = 1.0
    max_torque: float = 3.0


@dataclass(frozen=True)
class Guide:
    """A scripted hand: ``t`` (N,) s, ``xy`` (N, 2) m in the hole frame, ``press`` (N,) N."""

    t: np.ndarray
    xy: np.ndarray
    press: np.ndarray

    @property
    def lead_in(self) -> float:
        """Seconds before ``t = 0`` (the part of the guide that is not recorded)."""
        return max(0.0, -float(self.t[0]))

    @property
    def end(self) -> float:
        """The guide's last time (s): the recording's length."""
        return float(self.t[-1])

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, float] | None:
        """The target (2,) m, its velocity (2,) m/s and the press (N) at ``t`` s (the first
        row's before it); ``None`` once the guide has ended (the hand lets go)."""
        if t > self.t[-1]:
            return None
        i = int(np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.t) - 2))
        dt = self.t[i + 1] - self.t[i]
        s = float(np.clip((t - self.t[i]) / dt, 0.0, 1.0))
        vel = (self.xy[i + 1] - self.xy[i]) / dt if self.t[0] <= t else np.zeros(2)
        xy = self.xy[i] + s * (self.xy[i + 1] - self.xy[i])
        return xy, vel, float(self.press[i] + s * (self.press[i + 1] - self.press[i]))

    def to_csv(self) -> str:
        """The guide as CSV text (``t,x,y,press``)."""
        rows = [",".join(HEADER)]
        for t, (x, y), p in zip(self.t, self.xy, self.press, strict=True):
            rows.append(f"{t:.4f},{x:.6f},{y:.6f},{p:.3f}")
        return "\n".join(rows) + "\n"


def parse_guide(text: str, name: str) -> Guide:
    """The guide in CSV ``text`` (from ``name``); :class:`GuideError` naming ``name`` and the
    fix for anything a hand cannot follow."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    if not lines or tuple(c.strip() for c in lines[0].split(",")) != HEADER:
        raise GuideError(f"{name}: the first line must be t,x,y,press: {FIX}")
    if not 2 <= len(lines) - 1 <= MAX_ROWS:
        raise GuideError(f"{name}: needs 2 to {MAX_ROWS} rows, has {len(lines) - 1}: {FIX}")
    rows = np.empty((len(lines) - 1, 4))
    for k, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        try:
            if len(cells) != 4:
                raise ValueError
            rows[k - 2] = [float(c) for c in cells]
        except ValueError:
            raise GuideError(f"{name} line {k}: needs 4 numbers (t,x,y,press): {FIX}") from None
    return _checked(rows, name)


def _checked(rows: np.ndarray, name: str) -> Guide:
    t, xy, press = rows[:, 0], rows[:, 1:3], rows[:, 3]
    bad: str | None = None
    if not np.all(np.isfinite(rows)):
        bad = "has a value that is not a finite number"
    elif np.any(np.diff(t) <= 0):
        bad = "t must increase strictly from row to row"
    elif t[-1] <= 0 or t[-1] - t[0] > MAX_DURATION:
        bad = f"t must end after 0 s and span at most {MAX_DURATION:g} s"
    elif np.any(np.abs(xy) > MAX_REACH):
        bad = f"x, y must stay within {MAX_REACH} m of the hole (hole frame, m)"
    elif np.any(np.abs(press) > MAX_PRESS):
        bad = f"press must be within +-{MAX_PRESS:g} N (the hand's downward push; < 0 lifts)"
    if bad is not None:
        raise GuideError(f"{name}: {bad}: {FIX}")
    return Guide(t.copy(), xy.copy(), press.copy())


def read_guide(path: Path) -> Guide:
    """The guide in ``path`` (see the module docstring); :class:`GuideError` otherwise."""
    try:
        if path.is_dir():
            raise IsADirectoryError(21, "is a folder")
        if path.stat().st_size > MAX_BYTES:
            raise GuideError(f"--hand {path}: larger than {MAX_BYTES // 1_000_000} MB: {FIX}")
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise GuideError(f"--hand {path}: cannot read it ({exc.strerror}): {FIX}") from None
    except UnicodeDecodeError:
        raise GuideError(f"--hand {path}: not a text file: {FIX}") from None
    return parse_guide(text, f"--hand {path}")


def sweep_guide(
    start: tuple[float, float] = (-0.024, 0.018),
    pitch: float = 0.0025,
    halfwidth: float = 0.015,
    speed: float = 0.012,
    press: float = 6.0,
    seed: int = 0,
) -> Guide:
    """A blind search from ``start`` (hole frame, m) drawn like the teacher's sweep: the lead-in
    (t < 0) lifts the part (out of the hole, if it is in), carries it over ``start`` and
    lowers it;
    then passes ``2 halfwidth`` wide across the direction to the hole, ``pitch`` apart, at
    ``speed`` m/s, the last one ending over the hole, held there 3 s. ``seed`` draws the
    side the passes start on and a slow wander of the hand (0.3 mm)."""
    rng = np.random.default_rng(seed)
    p0 = np.asarray(start, dtype=float)
    span = float(np.linalg.norm(p0))
    if span < 2 * pitch:
        raise GuideError(f"sweep start {start} is within {2 * pitch} m of the hole: start further")
    u = -p0 / span
    v = np.array([-u[1], u[0]]) * rng.choice([-1.0, 1.0])
    rows = int(math.floor(span / pitch))
    corners = [np.zeros(2)]
    side = 1.0
    for k in range(rows):
        corners += [
            np.array([k * pitch, side * halfwidth]),
            np.array([(k + 1) * pitch, side * halfwidth]),
        ]
        side = -side
    corners.append(np.array([span, 0.0]))
    local = np.array(corners)
    path = p0 + local[:, :1] * u + local[:, 1:] * v
    seg = np.linalg.norm(np.diff(path, axis=0), axis=1)
    t = np.concatenate([[0.0], np.cumsum(seg) / speed])
    path = (
        path + rng.normal(0.0, 3e-4, path.shape) * (np.arange(len(path)) < len(path) - 1)[:, None]
    )
    # the lead-in: lift (out of the hole, where the last demonstration left the part), carry
    # the part over the start, lower it, press
    lead_t = np.array([-7.0, -5.8, -5.7, -4.7, -4.6, -0.5])
    lead_xy = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], p0, p0, p0])
    lead_press = [-4.0, -4.0, 0.0, 0.0, 3.0, 3.0]
    t = np.concatenate([lead_t, t, [t[-1] + 3.0]])
    xy = np.concatenate([lead_xy, path, path[-1:]])
    pr = np.concatenate([lead_press, np.full(len(path) + 1, press)])
    return Guide(t, xy, pr)


def main(argv: list[str] | None = None) -> None:
    """Write a sweep guide: ``TASK OUT.csv [--start DX DY] [--seed N] [--press N]``."""
    parser = argparse.ArgumentParser(description="write a scripted hand's search guide (CSV)")
    parser.add_argument("out", type=Path)
    parser.add_argument("--start", type=float, nargs=2, default=(-0.024, 0.018))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--press", type=float, default=6.0)
    args = parser.parse_args(argv)
    try:
        guide = sweep_guide(tuple(args.start), press=args.press, seed=args.seed)
        atomic_write_text(args.out, guide.to_csv(), what="guide")
    except TeachfitError as exc:
        print(f"error: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    print(f"guide ({guide.end:.1f} s, lead-in {guide.lead_in:.1f} s) -> {args.out}")


if __name__ == "__main__":
    main()
