"""Tests of the bounded CSV reader: every fault of a CSV file refused at its line, in one line."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.column_map import ColumnMap
from teachfit.demonstrations.csv_table import MAX_LINE_CHARS, read_table

HEADER = "t,x,y,z,note"
ROWS = [f"{i * 0.05:.2f},0.{i:03d},0.2,0.3,ok" for i in range(6)]
GOOD = "\n".join([HEADER, *ROWS]) + "\n"
NAMES = ["t", "x", "y", "z"]


def _edit(line: int, text: str) -> str:
    """GOOD with (1-based) line ``line`` replaced by ``text``."""
    lines = GOOD.splitlines()
    lines[line - 1] = text
    return "\n".join(lines) + "\n"


def _read(path: Path, delimiter: str = ","):
    return read_table(path, NAMES, delimiter, time=True, marker=None)


def test_good_file_and_dialects(tmp_path: Path) -> None:
    variants = {
        "plain": GOOD.encode(),
        "bom": b"\xef\xbb\xbf" + GOOD.encode(),
        "crlf": GOOD.replace("\n", "\r\n").encode(),
        "cr": GOOD.replace("\n", "\r").encode(),
        "quoted": "\n".join(
            ",".join(f'"{c}"' for c in line.split(",")) for line in GOOD.splitlines()
        ).encode(),
        "trailing delimiter": GOOD.replace("\n", ",\n").encode(),
    }
    for label, data in variants.items():
        path = tmp_path / f"{label}.csv"
        path.write_bytes(data)
        table = _read(path)
        assert table.values.shape == (6, 4), label
        np.testing.assert_allclose(table.values[:, 1], np.arange(6) / 1000)
        assert list(table.lines) == [2, 3, 4, 5, 6, 7] and table.note == "", label
        assert table.times is not None and table.times[0] == "0.00"
    semi = tmp_path / "semi.csv"
    semi.write_text(GOOD.replace(",", ";"))
    assert _read(semi, ";").values.shape == (6, 4)


@pytest.mark.parametrize(
    ("data", "row", "match"),
    [
        (_edit(4, "0.10,0.002,0.2," + "9" * (MAX_LINE_CHARS + 10)), 4, "longer than 65536"),
        (_edit(4, '"0.10,0.002,0.2,0.3,ok'), 4, "unclosed"),
        (_edit(7, '0.25,0.005,0.2,0.3,"ok'), 7, "unclosed"),  # open at the end of the file
        (_edit(3, "0.05,0.001,0.2,0.3,ok,7"), 3, "the row has 6 cells, the header names 5"),
        (_edit(3, "0.05,0.001,0.2"), 3, "only 3 cells"),
        (_edit(3, "0.05,0,001,0.2,0.3,ok"), 3, "the row has 6 cells"),
        (_edit(5, "0.15,abc" + "d" * 500 + ",0.2,0.3,ok"), 5, r"'abcd.*\(503 characters\)"),
        (GOOD.replace(",", ";").replace(".", ","), 1, "delimiter ';'\\? set delimiter = \";\""),
        (GOOD.replace(",", "\t"), 1, r'set delimiter = "\\t"'),
        ("", 1, "empty file"),
    ],
)
def test_faults_name_the_line(tmp_path: Path, data: str, row: int, match: str) -> None:
    path = tmp_path / "log.csv"
    path.write_text(data)
    with pytest.raises(DatasetError, match=match) as info:
        _read(path)
    assert info.value.row == row and info.value.path == str(path)
    assert "\n" not in str(info.value) and len(str(info.value)) < 400


def test_decimal_comma_is_named(tmp_path: Path) -> None:
    path = tmp_path / "log.csv"
    path.write_text(GOOD.replace(",", ";").replace(".", ","))
    with pytest.raises(DatasetError, match="not a number: '0,00' \\(a decimal comma") as info:
        _read(path, ";")
    assert (info.value.row, info.value.column) == (2, "t")


@pytest.mark.parametrize(
    ("data", "row", "match"),
    [
        (GOOD.encode()[:40] + b"\x00" + GOOD.encode()[40:], 3, "NUL byte"),
        (GOOD.encode("utf-16"), None, "UTF-16 text: save it as UTF-8"),
        (GOOD.encode("utf-16-le"), 1, "NUL byte"),
        (gzip.compress(GOOD.encode(), mtime=0), None, "gzip file"),
        (GOOD.encode()[:50] + b"\xe9" + GOOD.encode()[50:], 3, "not UTF-8 text .* at byte 50"),
    ],
)
def test_binary_and_encodings(tmp_path: Path, data: bytes, row: int | None, match: str) -> None:
    path = tmp_path / "log.csv"
    path.write_bytes(data)
    with pytest.raises(DatasetError, match=match) as info:
        _read(path)
    assert info.value.row == row


def test_a_huge_file_without_line_ends_is_refused_at_line_one(tmp_path: Path) -> None:
    path = tmp_path / "log.csv"
    path.write_text("1," * 2_000_000)  # 4 MB, no newline: refused after one bounded read
    with pytest.raises(DatasetError, match="longer than") as info:
        _read(path)
    assert info.value.row == 1


@pytest.mark.parametrize("delimiter", [".", "-", "e", "1", '"', "\n", "\x00"])
def test_delimiters_that_cannot_separate_cells(delimiter: str) -> None:
    with pytest.raises(DatasetError, match="cannot separate cells") as info:
        ColumnMap(time="t", x="x", y="y", z="z", delimiter=delimiter)
    assert info.value.column == "delimiter"
