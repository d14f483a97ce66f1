"""The parts suite's figure: success per part x method x robot with Wilson 95 % intervals."""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from teachfit.metrics.stats import SuccessSummary  # noqa: E402
from teachfit.viz.output import save_figure  # noqa: E402

#: one row of the figure: part, method, robot and its batch's summary
Cell = tuple[str, str, str, SuccessSummary]


def parts_figure(cells: Sequence[Cell], title: str = "", goal: float | None = 0.9) -> Figure:
    """One bar group per part (in the order first seen), one bar per method x robot (hatched
    for the second robot on), each with its Wilson 95 % interval; ``goal`` a dashed line."""
    parts = list(dict.fromkeys(c[0] for c in cells))
    series = list(dict.fromkeys((c[1], c[2]) for c in cells))
    robots = list(dict.fromkeys(c[2] for c in cells))
    methods = list(dict.fromkeys(c[1] for c in cells))
    by = {(c[0], c[1], c[2]): c[3] for c in cells}
    width = 0.8 / max(len(series), 1)
    fig, ax = plt.subplots(figsize=(max(7.0, 1.6 * len(parts) + 3.5), 4.2), layout="constrained")
    colors = plt.get_cmap("tab10")
    for j, (method, robot) in enumerate(series):
        xs, rate, err = [], [], []
        for i, part in enumerate(parts):
            s = by.get((part, method, robot))
            if s is None:
                continue
            xs.append(i + (j - (len(series) - 1) / 2) * width)
            rate.append(100 * s.rate)
            # at 0 % or 100 % the Wilson bound equals the rate up to rounding: never below 0
            err.append((max(0.0, 100 * (s.rate - s.low)), max(0.0, 100 * (s.high - s.rate))))
        ax.bar(
            xs, rate, width, yerr=np.array(err).T.reshape(2, -1), capsize=2,
            color=colors(methods.index(method)), hatch="//" if robots.index(robot) else None,
            edgecolor="k", linewidth=0.4, label=f"{method} ({robot})",
        )  # fmt: skip
    if goal is not None:
        ax.axhline(100 * goal, color="0.3", ls="--", lw=0.8)
    ax.set_xticks(range(len(parts)), parts, rotation=15, fontsize=8)
    ax.set_ylim(0, 105)
    ax.set_ylabel("success (%), Wilson 95 % interval")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title(textwrap.fill(title, 100), fontsize=8)
    return fig


def save_parts_figure(cells: Sequence[Cell], path: str | Path, title: str = "") -> Path:
    """:func:`parts_figure` written to ``path`` (the format from its suffix)."""
    return save_figure(parts_figure(cells, title), path)
