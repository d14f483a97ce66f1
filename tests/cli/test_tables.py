"""Tables fit the console: whole where they fit, one block per row where they do not."""

from __future__ import annotations

from rich.console import Console
from rich.table import Table

from teachfit.cli.tables import print_markdown, print_table

CELLS = ("tshix", "29/30 = 97 % [83, 99]", "25/30 = 83 % [66, 93]", "17.7 s", "73 ms (61.9 s)")


def _table() -> Table:
    table = Table(title="Table I")
    for col in ("method", "ours [95 % CI]", "paper [95 % CI]", "median time", "plan"):
        table.add_column(col)
    table.add_row(*CELLS)
    table.add_row("ergodic", *CELLS[1:])
    return table


def _render(width: int, draw) -> list[str]:
    console = Console(width=width, record=True, color_system=None)
    draw(console)
    return console.export_text().splitlines()


def test_narrow_consoles_get_one_block_per_row_with_whole_cells() -> None:
    lines = _render(60, lambda c: print_table(_table(), c))
    assert all(len(ln) <= 60 for ln in lines)
    for cell in CELLS:  # no cell is cut into stubs
        assert any(cell in ln for ln in lines), cell
    assert any(ln.startswith("ours [95 % CI]") for ln in lines)


def test_wide_consoles_get_the_table_at_full_width() -> None:
    lines = _render(200, lambda c: print_table(_table(), c))
    row = next(ln for ln in lines if "tshix" in ln)
    assert all(cell in row for cell in CELLS)  # one row, one line


def test_markdown_tables_go_the_same_way() -> None:
    text = "**results**\n\n| task | method | best cost (s) |\n| --- | --- | --- |\n"
    text += "| key | lhs | 0.3 |\n"
    lines = _render(30, lambda c: print_markdown(text, c))
    assert "results" in lines[0] and any(ln.startswith("best cost (s)") for ln in lines)
