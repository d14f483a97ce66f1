"""Tables that stay readable at any width: whole where they fit, one block per row where not.

Rich shrinks a too-wide table by wrapping every cell into stubs ("29/3", "0 = 9", ...), which at
80 columns (a log file, CI output) is unreadable. :func:`print_table` prints a table as it is
when its natural width fits the console and otherwise as a vertical list: for each row, each
column's header beside its value. Wide terminals get the whole table at full width.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from rich.console import Console, RenderableType
from rich.markdown import Markdown
from rich.measure import Measurement
from rich.table import Table
from rich.text import Text

from teachfit.cli.common import console as default_console

__all__ = ["emit_table", "markdown_table", "print_markdown", "print_table"]


def _cells(table: Table) -> list[list[RenderableType]]:
    columns = table.columns
    return [[col._cells[i] for col in columns] for i in range(table.row_count)]


def print_table(table: Table, console: Console | None = None) -> None:
    """Print ``table`` whole when it fits ``console``'s width, else one block per row."""
    con = console or default_console
    need = Measurement.get(con, con.options.update_width(100_000), table).maximum
    if need <= con.width or not table.columns:
        con.print(table)
        return
    if table.title:
        con.print(Text.from_markup(str(table.title), style="italic"))
    headers = [str(col.header) for col in table.columns]
    for k, row in enumerate(_cells(table)):
        grid = Table.grid(padding=(0, 2))
        grid.add_column(style="bold", no_wrap=True)
        grid.add_column(overflow="fold")
        for head, cell in zip(headers, row, strict=True):
            grid.add_row(head, cell)
        con.rule(f"{k + 1}/{table.row_count}", align="left", style="dim")
        con.print(grid)
    if table.caption:
        con.print(Text.from_markup(str(table.caption), style="dim"))


def emit_table(
    title: str, cols: Sequence[str], rows: Sequence[Sequence[str]], markdown: Path | None
) -> None:
    """Print a right-justified table of ``rows`` under ``title`` and, with ``markdown``, append
    it there as a markdown table (:func:`~teachfit.cli.common.append_markdown`)."""
    from teachfit.cli.common import append_markdown

    table = Table(title=title)
    for col in cols:
        table.add_column(col, justify="right")
    for cells in rows:
        table.add_row(*cells)
    print_table(table)
    if markdown is not None:
        lines = [f"\n**{title}**\n", "| " + " | ".join(cols) + " |", "|" + " --- |" * len(cols)]
        lines += ["| " + " | ".join(c) + " |" for c in rows]
        append_markdown(markdown, "\n".join(lines))


def markdown_table(lines: list[str], title: str | None = None) -> Table:
    """A rich table from the lines of a markdown table (header, ``---`` rule, rows)."""

    def split(line: str) -> list[str]:
        return [c.strip() for c in line.strip().strip("|").split("|")]

    table = Table(title=title)
    for head in split(lines[0]):
        table.add_column(head.replace("**", ""))
    for line in lines[2:]:
        table.add_row(*(c.replace("**", "").replace("`", "") for c in split(line)))
    return table


def print_markdown(text: str, console: Console | None = None) -> None:
    """Print markdown ``text``: prose through rich's Markdown, each table by :func:`print_table`."""
    con = console or default_console
    prose: list[str] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].lstrip().startswith("|") and i + 1 < len(lines) and "---" in lines[i + 1]:
            if prose:
                con.print(Markdown("\n".join(prose)))
                prose = []
            j = i
            while j < len(lines) and lines[j].lstrip().startswith("|"):
                j += 1
            print_table(markdown_table(lines[i:j]), con)
            i = j
        else:
            prose.append(lines[i])
            i += 1
    if any(p.strip() for p in prose):
        con.print(Markdown("\n".join(prose)))
