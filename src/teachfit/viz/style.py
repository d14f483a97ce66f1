"""One style for every figure: units written "x (mm)", start and end markers on every path, a
legend entry for every marker, and titles that name what was run (method, N, seed)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.typing import ColorType  # noqa: E402

__all__ = ["START", "END", "axis_label", "end_handles", "mark_ends", "run_title"]

#: marker of a path's first point (hollow circle) and of its last point (filled square)
START: dict[str, Any] = {"marker": "o", "ms": 6, "mfc": "white", "mew": 1.2, "ls": "none"}
END: dict[str, Any] = {"marker": "s", "ms": 5, "ls": "none"}


def axis_label(name: str, unit: str, frame: str | None = None) -> str:
    """``"x (mm)"``, or ``"x in panda_link0 (mm)"`` with a frame."""
    return f"{name}{f' in {frame}' if frame else ''} ({unit})"


def mark_ends(ax: plt.Axes, xs: np.ndarray, ys: np.ndarray, color: ColorType = "k") -> None:
    """Draw the start and end markers of the path ``(xs, ys)`` in ``color``."""
    xs, ys = np.asarray(xs), np.asarray(ys)
    ax.plot(xs[:1], ys[:1], mec=color, **START)
    ax.plot(xs[-1:], ys[-1:], color=color, mec=color, **END)


def end_handles(color: ColorType = "0.3") -> list[Line2D]:
    """Legend entries explaining :func:`mark_ends`' markers."""
    return [
        Line2D([], [], mec=color, label="start", **START),
        Line2D([], [], color=color, mec=color, label="end", **END),
    ]


def run_title(
    what: str,
    *,
    method: str | None = None,
    n: int | None = None,
    seed: int | None = None,
    extra: Sequence[str] = (),
) -> str:
    """``"what: tshix, N = 300, seed 4"`` from the parts that are known."""
    parts = [
        p
        for p in (
            method,
            None if n is None else f"N = {n}",
            None if seed is None else f"seed {seed}",
            *extra,
        )
        if p
    ]
    return what + (f" ({', '.join(parts)})" if parts else "")
