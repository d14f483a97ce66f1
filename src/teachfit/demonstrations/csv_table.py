"""Read the mapped columns of a CSV log one line at a time, in bounded memory.

The file is read as UTF-8 text (a byte-order mark is skipped), one line at a time and at most
:data:`MAX_LINE_CHARS` characters a line; only the mapped numbers are kept (8 bytes each), plus
the time cells as text (for exact epoch differences) and the marker cells. So a file without
newlines, a 200 k-character cell or an unclosed quote that would run to the end of the file is
refused at the line where it starts, never read whole.

Refused, each in one :class:`~teachfit.core.errors.DatasetError` naming the file, the line
(1-based, the header is line 1), the CSV column where there is one, and the fix: a binary,
compressed, UTF-16 or otherwise non-UTF-8 file, NUL bytes, a line over the limit, a quoted cell
that runs over the end of its line, a row with more non-empty cells than the header names, a
short row, and a cell that is not a number (with a hint for a decimal comma).

A last line cut short while the log was being written (no newline at the end of the file and
fewer cells than the header, or a last number with fewer decimals than that column has in every
other row) is dropped, with a note saying so.
"""

from __future__ import annotations

import codecs
import csv
import json
from array import array
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import IO

import numpy as np

from teachfit.core.errors import DatasetError

#: the longest line read (characters, with its line end); a log line is a few hundred
MAX_LINE_CHARS = 65_536
#: how much of a bad cell or header an error message shows (characters)
SHOW_CHARS = 40
_MAGIC = {
    b"\xff\xfe": "UTF-16 text: save it as UTF-8",
    b"\xfe\xff": "UTF-16 text: save it as UTF-8",
    b"\x1f\x8b": "a gzip file: decompress it first",
    b"PK\x03\x04": "a zip archive (or a spreadsheet): extract or export the CSV first",
    b"\x89HDF": "an HDF5 file, not a CSV log",
}


def show(cell: str) -> str:
    """``cell`` for a message: its repr, cut to :data:`SHOW_CHARS` characters."""
    if len(cell) <= SHOW_CHARS:
        return repr(cell)
    return f"{cell[:SHOW_CHARS]!r}... ({len(cell)} characters)"


def is_float(cell: str) -> bool:
    """Whether ``float(cell)`` parses."""
    try:
        float(cell)
    except ValueError:
        return False
    return True


def decimals(cell: str) -> int | None:
    """Digits after the decimal point of a plain number, or None if ``cell`` is not one."""
    text = cell.strip()
    if not is_float(text) or "e" in text.lower():
        return None
    return len(text.partition(".")[2])


@dataclass
class CsvTable:
    """The mapped columns of a CSV log.

    ``values`` (N, K) float64 in the order of the names asked for, ``lines`` (N,) their line
    numbers, ``times`` the raw cells of the first name (the time column) if asked, ``marker``
    the marker cells if asked, ``note`` what was dropped ("" if nothing).
    """

    values: np.ndarray
    lines: np.ndarray
    times: list[str] | None
    marker: tuple[str, ...] | None
    note: str


class _Lines:
    """Lines of an open text file, each at most :data:`MAX_LINE_CHARS` characters; refuses a
    record (a CSV row) that asks for a second line: a quoted cell running over its line end."""

    def __init__(self, handle: IO[str], fail: partial[DatasetError]) -> None:
        self.handle, self.fail = handle, fail
        self.given = 0  # lines handed to the CSV reader
        self.done = 0  # lines the rows read so far end on
        self.last = ""

    def __iter__(self) -> Iterator[str]:
        return self

    def __next__(self) -> str:
        if self.given > self.done:
            raise self.fail(
                "a quoted cell runs past the end of its line (an unclosed '\"'?): close the "
                "quote or remove it; a log's cells are one line each",
                row=self.done + 1,
            )
        try:
            line = self.handle.readline(MAX_LINE_CHARS + 1)
        except UnicodeDecodeError as exc:
            bad_row, offset = _first_bad_byte(Path(self.handle.name))
            raise self.fail(
                f"not UTF-8 text ({exc.reason} at byte {offset}): save the log as UTF-8",
                row=bad_row,
            ) from exc
        if not line:
            raise StopIteration
        self.given += 1
        if len(line) > MAX_LINE_CHARS:
            raise self.fail(
                f"the line is longer than {MAX_LINE_CHARS} characters (a cell this long is not "
                "a log value, or the file has no line ends): check the file and the delimiter",
                row=self.given,
            )
        if "\x00" in line:
            raise self.fail(
                "the line holds a NUL byte: not a text CSV log (a binary file, UTF-16 text or a "
                "damaged copy); export the log as UTF-8 text",
                row=self.given,
            )
        self.last = line
        return line


def _first_bad_byte(path: Path) -> tuple[int, int]:
    """(line, byte offset) of the first byte of ``path`` that is not UTF-8, read in chunks."""
    decoder = codecs.getincrementaldecoder("utf-8")()
    line, offset = 1, 0
    with path.open("rb") as raw:
        for chunk in iter(lambda: raw.read(1 << 16), b""):
            kept = len(decoder.getstate()[0])  # bytes of a character cut by the last chunk
            try:
                decoder.decode(chunk)
            except UnicodeDecodeError as exc:
                at = max(exc.start - kept, 0)
                return line + chunk[:at].count(b"\n"), offset + at
            line += chunk.count(b"\n")
            offset += len(chunk)
    return line, offset


def _rows(
    path: Path, delimiter: str, fail: partial[DatasetError]
) -> Iterator[tuple[int, list[str], bool]]:
    """(line number, cells, whether the line ends with a newline) of each non-blank row."""
    try:
        with path.open("rb") as raw:
            head = raw.read(4)
        handle = path.open(encoding="utf-8-sig", newline="")
    except OSError as exc:
        raise fail(f"cannot read ({exc.strerror})") from exc
    what = next((why for magic, why in _MAGIC.items() if head.startswith(magic)), None)
    with handle:
        if what is not None:
            raise fail(f"not a CSV log: {what}")
        lines = _Lines(handle, fail)
        reader = csv.reader(lines, delimiter=delimiter, strict=False)
        while True:
            try:
                row = next(reader)
            except StopIteration:
                return
            except csv.Error as exc:
                raise fail(
                    f"not readable as CSV ({exc}): check the file", row=lines.done + 1
                ) from exc
            lines.done = reader.line_num
            if row and not (len(row) == 1 and not row[0].strip()):
                yield reader.line_num, row, lines.last.endswith(("\n", "\r"))


def _header_text(header: list[str]) -> str:
    shown = ", ".join(show(h) for h in header[:12])
    count = f"{len(header)} column" + ("s" if len(header) != 1 else "")
    return f"[{shown}{', ...' if len(header) > 12 else ''}] ({count})"


def _check_header(header: list[str], wanted: list[str], delimiter: str, fail) -> None:
    for name in wanted:
        if header.count(name) == 1:
            continue
        problem = "appears more than once in" if name in header else "is not in"
        hint = ""
        if len(header) == 1:
            other = next((d for d in ",;\t| " if d != delimiter and d in header[0]), None)
            if other is not None:
                hint = (
                    f" (one column: is the delimiter {other!r}? set delimiter = "
                    f"{json.dumps(other)} in the column map)"
                )
        raise fail(f"column {problem} the header {_header_text(header)}{hint}", row=1, column=name)


def _bad_cell(row: list[str], index: list[int], names: list[str], line: int, fail) -> None:
    """Raise for the first mapped cell of ``row`` that is missing or not a number."""
    for i, name in zip(index, names, strict=True):
        if i >= len(row):
            raise fail(f"line has only {len(row)} cells", row=line, column=name)
        cell = row[i]
        if not is_float(cell):
            hint = ""
            if "," in cell and is_float(cell.replace(",", ".")):
                hint = " (a decimal comma: export the log with decimal points)"
            raise fail(f"not a number: {show(cell)}{hint}", row=line, column=name)


class _Collect:
    """The mapped cells of the rows, kept compactly, and the last column's decimals."""

    def __init__(self, header: list[str], index: list[int], marker: int | None, time: bool):
        self.header, self.index, self.marker, self.time = header, index, marker, time
        self.values = array("d")
        self.lines = array("q")
        self.times: list[str] = []
        self.markers: list[str] = []
        self.digits: Counter[int | None] = Counter()

    def add(self, line: int, row: list[str], fail) -> None:
        width = len(self.header)
        if len(row) > width and any(cell.strip() for cell in row[width:]):
            raise fail(
                f"the row has {len(row)} cells, the header names {width}: a delimiter inside "
                "a cell or a missing header name shifts the columns; quote that cell or fix the "
                "header",
                row=line,
            )
        try:
            self.values.extend([float(row[i]) for i in self.index])
        except (ValueError, IndexError):
            _bad_cell(row, self.index, [self.header[i] for i in self.index], line, fail)
            raise
        if self.marker is not None:
            if len(row) <= self.marker:
                raise fail("line has no marker cell", row=line, column=self.header[self.marker])
            self.markers.append(row[self.marker].strip())
        if self.time:
            self.times.append(row[self.index[0]])
        self.lines.append(line)
        if len(row) >= width:
            self.digits[decimals(row[width - 1])] += 1


def _truncated(last: list[str], header: list[str], digits: Counter) -> str | None:
    """Why the last row looks cut short, or None (only asked without a final newline);
    ``digits`` counts the decimals of the last column in the other rows."""
    if len(last) < len(header):
        return f"it has {len(last)} of {len(header)} cells"
    col = len(header) - 1
    if len(digits) != 1 or None in digits or digits.total() < 2:
        return None
    typical = next(iter(digits))
    here = decimals(last[col])
    if here is None or here < typical:
        return (
            f"its last number {show(last[col].strip())} has fewer decimals than the {typical} of "
            f"every other row in column {header[col]!r}"
        )
    return None


def read_table(
    path: Path, names: list[str], delimiter: str, *, time: bool, marker: str | None
) -> CsvTable:
    """The columns ``names`` (the first is the time column if ``time``) and ``marker`` of the
    CSV log ``path``.

    Raises
    ------
    DatasetError
        Naming the file, the line and the column, for the faults listed in the module docstring.
    """
    fail = partial(DatasetError, path=str(path))
    rows = _rows(path, delimiter, fail)
    header = [h.strip() for h in next(rows, (1, [], True))[1]]
    if not header:
        raise fail("empty file, expected a header line", row=1)
    _check_header(header, names + ([marker] if marker else []), delimiter, fail)
    where = None if marker is None else header.index(marker)
    keep = _Collect(header, [header.index(n) for n in names], where, time)
    pending = None
    for line, row, ended in rows:
        if pending is not None:
            keep.add(pending[0], pending[1], fail)
        pending = (line, row, ended)
    note = ""
    if pending is not None:
        why = None if pending[2] else _truncated(pending[1], header, keep.digits)
        if why is None:
            keep.add(pending[0], pending[1], fail)
        else:
            note = (
                f"file {path}, row {pending[0]}: the last line is cut short (no newline at the "
                f"end of the file and {why}); dropped it"
            )
    values = np.frombuffer(keep.values, dtype=np.float64).reshape(-1, len(names))
    return CsvTable(
        values=values.copy(),
        lines=np.frombuffer(keep.lines, dtype=np.int64).copy(),
        times=keep.times if time else None,
        marker=tuple(keep.markers) if marker is not None else None,
        note=note,
    )
