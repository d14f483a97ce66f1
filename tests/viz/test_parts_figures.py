"""The parts suite's figure: one bar group per part, one bar per method x robot."""

from __future__ import annotations

from pathlib import Path

from media_checks import read_png

from teachfit.metrics.stats import summarize
from teachfit.viz.parts_figures import Cell, parts_figure, save_parts_figure


def _cells() -> list[Cell]:
    out: list[Cell] = []
    for part in ("round8", "rect12x8", "round16"):
        for robot in ("floating", "fr3"):
            for k, method in enumerate(("skill", "search")):
                out.append(
                    (
                        part,
                        method,
                        robot,
                        summarize([True] * (3 + k) + [False] * (1 - k), [1.0] * 4),
                    )
                )
    return out


def test_one_bar_group_per_part_with_an_interval_per_bar() -> None:
    fig = parts_figure(_cells(), "suite")
    ax = fig.axes[0]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["round8", "rect12x8", "round16"]
    bars = [p for c in ax.containers for p in getattr(c, "patches", [])]
    assert len(bars) == 3 * 2 * 2  # parts x methods x robots
    centres = sorted(b.get_x() + b.get_width() / 2 for b in bars)
    groups = [round(c) for c in centres]  # each bar within its part's group around 0, 1, 2
    assert groups == sorted([0] * 4 + [1] * 4 + [2] * 4)
    assert len(ax.get_legend().get_texts()) == 4
    heights = sorted({round(b.get_height()) for b in bars})
    assert heights == [75, 100]


def test_the_figure_is_written(tmp_path: Path) -> None:
    path = save_parts_figure(_cells()[:2], tmp_path / "parts.png", "t")
    read_png(path)


def test_rates_of_none_and_all_draw_with_their_intervals() -> None:
    """0/10 and 10/10: the Wilson bound sits on the rate up to rounding, never a negative bar."""
    cells: list[Cell] = [
        ("round8", "skill", "floating", summarize([False] * 10, [1.0] * 10)),
        ("round8", "search", "floating", summarize([True] * 10, [1.0] * 10)),
        ("round16", "skill", "floating", summarize([True] * 9 + [False], [1.0] * 10)),
    ]
    ax = parts_figure(cells, "edges").axes[0]
    heights = sorted(
        round(p.get_height()) for c in ax.containers for p in getattr(c, "patches", [])
    )
    assert heights == [0, 90, 100]
