"""Success against each task parameter over a sample of variants (``bench search --variants``).

One panel per grid axis: every variant is a point at its value of that axis, its success rate
with the Wilson 95 % interval as an error bar, one colour per method (slightly offset so that
they do not hide each other), and the goal as a dashed line.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402


class VariantRecord(TypedDict):
    """One variant's figure data: ``values`` axis -> value (as shown), ``rates`` method ->
    ``(successes, trials, low, high)`` (Wilson 95 % interval)."""

    values: dict[str, float]
    rates: dict[str, tuple[int, int, float, float]]


_COLOURS = {"tshix": "tab:blue", "ergodic": "tab:orange"}
_LABELS = {
    "peg_diameter_mm": "peg diameter (mm)",
    "clearance_mm": "diametral clearance (mm)",
    "friction": "friction coefficient",
    "chamfers": "chamfers (0 = sharp, 1 = chamfered)",
    "start_rz_deg": "start yaw half-range (deg)",
    "clearance_small_mm": "small-hole clearance (mm)",
    "clearance_large_mm": "large-hole clearance (mm)",
}


def success_by_parameter(
    records: Sequence[VariantRecord], title: str, goal: float | None = None
) -> Figure:
    """Panels of success rate (%) against each axis of ``records`` (dicts with ``values``:
    axis -> value, and ``rates``: method -> ``(successes, trials, low, high)``)."""
    if not records:
        raise ValueError("no variants to plot")
    axes_names = list(records[0]["values"])
    methods = sorted({m for r in records for m in r["rates"]})
    fig, axs = plt.subplots(1, len(axes_names), figsize=(3.6 * len(axes_names), 3.6), squeeze=False)
    for ax, name in zip(axs[0], axes_names, strict=True):
        xs = np.array([r["values"][name] for r in records], dtype=float)
        levels = np.unique(xs)
        step = float(np.min(np.diff(levels))) if levels.size > 1 else abs(levels[0]) or 1.0
        for k, method in enumerate(methods):
            pts = [
                (x, r["rates"][method])
                for x, r in zip(xs, records, strict=True)
                if method in r["rates"]
            ]
            if not pts:
                continue
            x = np.array([p[0] for p in pts]) + (k - (len(methods) - 1) / 2) * 0.08 * step
            s, n, lo, hi = (np.array([p[1][i] for p in pts], dtype=float) for i in range(4))
            rate = 100 * s / n
            err = np.vstack([rate - 100 * lo, 100 * hi - rate])
            ax.errorbar(
                x, rate, yerr=err, fmt="o", capsize=3, color=_COLOURS.get(method), label=method
            )
        if goal is not None:
            ax.axhline(100 * goal, ls="--", color="0.4", lw=1, label=f"goal {100 * goal:.0f} %")
        ax.set_xticks(levels)
        ax.set_xlim(levels[0] - 0.5 * step, levels[-1] + 0.5 * step)
        ax.set_xlabel(_LABELS.get(name, name))
        ax.set_ylim(-5, 105)
        ax.grid(alpha=0.3)
    axs[0][0].set_ylabel("success (%, Wilson 95 % interval)")
    axs[0][0].legend(loc="lower left", fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig
