"""Tests of CSV import and the TOML column map."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.csv_import import ColumnMap, import_csv

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
LOG = EXAMPLES / "robot_log.csv"
COLUMNS = EXAMPLES / "columns.toml"
HEADER = LOG.read_text().splitlines()[0].split(",")

BASIC = ColumnMap(time="time", x="x", y="y", z="z")


def edited_log(tmp_path: Path, line: int, column: str, value: str) -> Path:
    """Copy of the example log with the cell at (1-based line, column) replaced."""
    lines = LOG.read_text().splitlines()
    cells = lines[line - 1].split(",")
    cells[HEADER.index(column)] = value
    lines[line - 1] = ",".join(cells)
    out = tmp_path / "log.csv"
    out.write_text("\n".join(lines) + "\n")
    return out


def write(tmp_path: Path, text: str, name: str = "log.csv") -> Path:
    out = tmp_path / name
    out.write_text(text)
    return out


def test_example_files() -> None:
    columns = ColumnMap.from_toml(COLUMNS)
    assert columns.frame == "base" and columns.wrench_sign == -1
    assert columns.has_quat and columns.has_wrench
    demo = import_csv(LOG, columns, task="peg2d")
    assert demo.source == "imported" and demo.task == "peg2d" and demo.name == "robot_log"
    assert demo.frame == "base"
    assert demo.n_samples == 60
    assert demo.t[0] == 0.0
    assert demo.rate_hz == pytest.approx(20.0, rel=1e-9)
    assert demo.duration == pytest.approx(2.95, abs=1e-12)
    assert demo.meta["time_offset_s"] == pytest.approx(1718023402.150)
    first = [float(v) for v in LOG.read_text().splitlines()[1].split(",")[:14]]
    np.testing.assert_allclose(demo.pos[0], first[1:4])
    np.testing.assert_allclose(demo.quat[0], first[4:8], atol=1e-5)
    np.testing.assert_allclose(demo.wrench[0], -np.array(first[8:14]))  # wrench_sign = -1
    # in contact the log says the robot pushes down: the environment pushes the tool up
    assert np.all(demo.wrench[-10:, 2] > 1.0)
    assert np.all(np.diff(demo.pos[:, 2]) < 0)  # the tool descends in the base frame
    assert import_csv(LOG, columns, task="peg2d", name="run 7").name == "run 7"


def test_optional_groups_and_scales(tmp_path: Path) -> None:
    path = write(tmp_path, "ms;X mm;Y mm;Z mm\n1000;1;2;3\n1500;4;5;6\n\n2000;7;8;9\n")
    columns = ColumnMap(
        time="ms", x="X mm", y="Y mm", z="Z mm", time_scale=1e-3, length_scale=1e-3, delimiter=";"
    )
    demo = import_csv(path, columns, task="socket3d")
    np.testing.assert_allclose(demo.t, [0.0, 0.5, 1.0])
    np.testing.assert_allclose(demo.pos, np.arange(1, 10).reshape(3, 3) * 1e-3)
    np.testing.assert_array_equal(demo.quat, np.tile([1.0, 0.0, 0.0, 0.0], (3, 1)))
    assert demo.wrench is None and demo.frame == "world"
    assert demo.meta["time_offset_s"] == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("line", "column", "value", "match"),
    [
        (5, "tcp_y", "abc", "not a number: 'abc'"),
        (9, "fz", "", "not a number: ''"),
        (12, "tcp_qx", "nan", "non-finite"),
        (40, "tx", "-inf", "non-finite"),
        (20, "timestamp", "1718023403.000", "not strictly increasing"),  # equal to line 19
        (30, "timestamp", "1718023400", "not strictly increasing"),
        (7, "tcp_qw", "0.2", "norm"),
    ],
)
def test_cell_errors_name_line_and_column(
    tmp_path: Path, line: int, column: str, value: str, match: str
) -> None:
    path = edited_log(tmp_path, line, column, value)
    with pytest.raises(DatasetError, match=match) as info:
        import_csv(path, ColumnMap.from_toml(COLUMNS), task="peg2d")
    err = info.value
    assert (err.path, err.row, err.column) == (str(path), line, column)
    assert f"row {line}" in str(err) and repr(column) in str(err) and str(path) in str(err)


def test_unused_bad_cells_are_ignored(tmp_path: Path) -> None:
    path = edited_log(tmp_path, 5, "gripper_mm", "n/a")
    assert import_csv(path, ColumnMap.from_toml(COLUMNS), task="peg2d").n_samples == 60


def test_missing_column(tmp_path: Path) -> None:
    path = write(tmp_path, "time,x,y\n0,1,2\n1,2,3\n")
    with pytest.raises(DatasetError, match="not in the header") as info:
        import_csv(path, BASIC, task="a")
    assert (info.value.row, info.value.column) == (1, "z")


def test_short_line_and_blank_lines(tmp_path: Path) -> None:
    path = write(tmp_path, "time,x,y,z\n0,0,0,0\n\n1,1,1\n")
    with pytest.raises(DatasetError, match="only 3 cells") as info:
        import_csv(path, BASIC, task="a")
    assert (info.value.row, info.value.column) == (4, "z")


def test_too_few_samples(tmp_path: Path) -> None:
    one_row = write(tmp_path, "time,x,y,z\n0,0,0,0\n")
    with pytest.raises(DatasetError, match="1 data rows, need at least 2") as info:
        import_csv(one_row, BASIC, task="a")
    assert info.value.path == str(one_row)
    with pytest.raises(DatasetError, match="header") as info:
        import_csv(write(tmp_path, "", "empty.csv"), BASIC, task="a")
    assert info.value.row == 1
    with pytest.raises(DatasetError, match="cannot read"):
        import_csv(tmp_path / "missing.csv", BASIC, task="a")


def test_toml_errors(tmp_path: Path) -> None:
    base = COLUMNS.read_text()
    cases = [
        (base.replace("frame =", "colour = 'red'\nframe ="), "colour"),
        (base.replace('fz = "fz"', 'fz = "fz"\nfw = "fw"'), "fw"),
        (base.replace('x = "tcp_x"\n', ""), "x"),
        (base.replace('qz = "tcp_qz"\n', ""), "qz"),
        (base.replace('fx = "fx"\n', ""), "fx"),
        (base.replace("wrench_sign = -1", "wrench_sign = 2"), "wrench_sign"),
        (base.replace("length_scale = 1.0", "length_scale = 0.0"), "length_scale"),
        (base.replace('delimiter = ","', 'delimiter = ",;"'), "delimiter"),
        (base.replace('ty = "ty"', 'ty = "tx"'), "tx"),
    ]
    for text, column in cases:
        path = write(tmp_path, text, "columns.toml")
        with pytest.raises(DatasetError) as info:
            ColumnMap.from_toml(path)
        assert (info.value.column, info.value.path) == (column, str(path)), text
    with pytest.raises(DatasetError, match="invalid TOML"):
        ColumnMap.from_toml(write(tmp_path, "x = [", "broken.toml"))


def test_ten_thousand_rows_round_trip(tmp_path: Path) -> None:
    # the import speed is a benchmark figure (benchmarks/csv_import_speed.py), not a test
    rng = np.random.default_rng(0)
    n = 10_000
    t = 1.7e9 + np.arange(n) * 0.001
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    table = np.column_stack([t, rng.normal(size=(n, 3)), q, rng.normal(size=(n, 6))])
    header = ",".join(HEADER[:14])
    path = tmp_path / "big.csv"
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.9f")
    demo = import_csv(path, ColumnMap.from_toml(COLUMNS), task="a")
    assert demo.n_samples == n
    np.testing.assert_allclose(demo.t, np.arange(n) * 0.001, atol=1e-6)
    np.testing.assert_allclose(demo.pos, table[:, 1:4], atol=1e-9)
    # the same rotation row by row (a quaternion and its negation are one rotation)
    np.testing.assert_allclose(np.abs(np.sum(demo.quat * table[:, 4:8], axis=1)), 1.0, atol=1e-6)
    np.testing.assert_allclose(demo.wrench, -table[:, 8:14], atol=1e-9)  # wrench_sign = -1
