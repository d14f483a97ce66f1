"""Tests of CSV import: parsing, units, truncated last lines, logs without time."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.csv_import import ColumnMap, import_csv, read_csv_log

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
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
    log = read_csv_log(path, columns)  # 2 Hz: reading only, no plausibility checks
    np.testing.assert_allclose(log.t, [0.0, 0.5, 1.0])
    np.testing.assert_allclose(log.pos, np.arange(1, 10).reshape(3, 3) * 1e-3)
    np.testing.assert_array_equal(log.quat, np.tile([1.0, 0.0, 0.0, 0.0], (3, 1)))
    assert log.wrench is None and log.frame == "world"
    assert log.meta["time_offset_s"] == pytest.approx(1.0)
    assert list(log.rows) == [2, 3, 5]


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
        read_csv_log(path, BASIC)
    assert (info.value.row, info.value.column) == (1, "z")


def test_short_line_and_blank_lines(tmp_path: Path) -> None:
    path = write(tmp_path, "time,x,y,z\n0,0,0,0\n\n1,1,1\n")
    with pytest.raises(DatasetError, match="only 3 cells") as info:
        read_csv_log(path, BASIC)
    assert (info.value.row, info.value.column) == (4, "z")


def test_too_few_samples(tmp_path: Path) -> None:
    with pytest.raises(DatasetError, match="1 data rows, need at least 2") as info:
        read_csv_log(write(tmp_path, "time,x,y,z\n0,0,0,0\n"), BASIC)
    assert info.value.path is not None
    with pytest.raises(DatasetError, match="header") as info:
        read_csv_log(write(tmp_path, "", "empty.csv"), BASIC)
    assert info.value.row == 1
    with pytest.raises(DatasetError, match="cannot read"):
        read_csv_log(tmp_path / "missing.csv", BASIC)


def uncommented(path: Path) -> str:
    """The TOML text without its comment-only lines (the example documents every key)."""
    return "\n".join(line for line in path.read_text().splitlines() if not line.startswith("#"))


def test_toml_errors(tmp_path: Path) -> None:
    base = uncommented(COLUMNS)
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


def test_ten_thousand_rows(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    n = 10_000
    t = 1.7e9 + np.arange(n) * 0.001
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    table = np.column_stack([t, rng.normal(size=(n, 3)), q, rng.normal(size=(n, 6))])
    header = ",".join(HEADER[:14])
    path = tmp_path / "big.csv"
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.9f")
    log = read_csv_log(path, replace(ColumnMap.from_toml(COLUMNS), marker=None))
    assert log.n_samples == n
    np.testing.assert_allclose(log.t[-1], (n - 1) * 0.001, atol=1e-9)  # epoch stamps, exact
    np.testing.assert_allclose(log.quat, q, atol=1e-9)


def test_example_map_records_its_source() -> None:
    demo = import_csv(LOG, ColumnMap.from_toml(COLUMNS), task="peg2d")
    assert demo.meta["source_file"] == "robot_log.csv" and demo.meta["source_format"] == "csv"
    assert demo.meta["source_frame"] == "base" and demo.meta["wrench_sign"] == -1
    assert demo.meta["source_rows"] == [2, 61]


@pytest.mark.parametrize(
    ("cut", "why"),
    [
        (lambda line: line[: line.rindex(",")], "it has 15 of 16 cells"),
        (lambda line: line[:-1], "its last number '40.' has fewer decimals than the 1"),
    ],
)
def test_truncated_last_line_is_dropped_with_a_note(tmp_path: Path, cut, why: str) -> None:
    lines = LOG.read_text().splitlines()
    path = write(tmp_path, "\n".join([*lines[:-1], cut(lines[-1])]))  # no newline at the end
    log = read_csv_log(path, ColumnMap.from_toml(COLUMNS))
    assert log.n_samples == 59  # the cut line 61 is gone
    assert len(log.notes) == 1 and why in log.notes[0]
    assert f"file {path}, row 61: the last line is cut short" in log.notes[0]


def test_cut_inside_a_mapped_number_is_dropped(tmp_path: Path) -> None:
    lines = LOG.read_text().splitlines()[:-1]
    cells = lines[-1].split(",")
    lines[-1] = ",".join([*cells[:13], cells[13][:-2]])  # tz "-0.0064" cut to "-0.00"
    path = write(tmp_path, "\n".join(lines))
    log = read_csv_log(path, ColumnMap.from_toml(COLUMNS))
    assert log.n_samples == 58 and "row 60" in log.notes[0]


def test_complete_last_line_without_newline_is_kept(tmp_path: Path) -> None:
    path = write(tmp_path, LOG.read_text().rstrip("\n"))
    log = read_csv_log(path, ColumnMap.from_toml(COLUMNS))
    assert log.n_samples == 60 and log.notes == ()


def test_short_last_line_with_newline_is_an_error(tmp_path: Path) -> None:
    lines = LOG.read_text().splitlines()
    lines[-1] = ",".join(lines[-1].split(",")[:10])
    with pytest.raises(DatasetError, match="only 10 cells") as info:
        read_csv_log(write(tmp_path, "\n".join(lines) + "\n"), ColumnMap.from_toml(COLUMNS))
    assert info.value.row == 61


def test_log_without_time_column_needs_a_rate(tmp_path: Path) -> None:
    path = write(tmp_path, "x,y,z\n0,0,0\n1,1,1\n2,2,2\n")
    cmap = write(tmp_path, '[columns]\nx = "x"\ny = "y"\nz = "z"\n', "columns.toml")
    with pytest.raises(DatasetError) as info:
        ColumnMap.from_toml(cmap)
    message = str(info.value)
    assert str(cmap) in message and "rate_hz" in message and "--rate" in message
    log = read_csv_log(path, ColumnMap.from_toml(cmap, rate_hz=20.0))
    np.testing.assert_allclose(log.t, [0.0, 0.05, 0.1])
    assert "time_offset_s" not in log.meta and log.meta["rate_hz_given"] == 20.0
    text = cmap.read_text().replace("[columns]", "rate_hz = 4.0\n[columns]")
    with_rate = ColumnMap.from_toml(write(tmp_path, text, "rate.toml"))
    np.testing.assert_allclose(read_csv_log(path, with_rate).t, [0.0, 0.25, 0.5])
    with pytest.raises(DatasetError, match="--rate is for a log without a time column") as info:
        ColumnMap.from_toml(COLUMNS, rate_hz=20.0)
    assert info.value.path == str(COLUMNS)


def test_quaternion_list_in_either_order(tmp_path: Path) -> None:
    path = write(tmp_path, "t,x,y,z,a,b,c,d\n0,0,0,0,0.6,0,0,0.8\n1,0,0,0,0.6,0,0,0.8\n")
    base = '[columns]\ntime = "t"\nx = "x"\ny = "y"\nz = "z"\nquat = ["a", "b", "c", "d"]\n'
    wxyz = read_csv_log(path, ColumnMap.from_toml(write(tmp_path, base, "m.toml")))
    np.testing.assert_allclose(wxyz.quat[0], [0.6, 0.0, 0.0, 0.8])
    xyzw = 'quat_order = "x,y,z,w"\n' + base
    log = read_csv_log(path, ColumnMap.from_toml(write(tmp_path, xyzw, "m.toml")))
    np.testing.assert_allclose(log.quat[0], [0.8, 0.6, 0.0, 0.0])
    assert log.meta["quat_order"] == "x,y,z,w"
    bad = [
        ('quat_order = "z,y,x,w"\n' + base, "quat_order"),
        (base.replace('"d"]', '"d", "e"]'), "quat"),
        (uncommented(COLUMNS).replace("[columns]", 'quat_order = "x,y,z,w"\n[columns]'), "quat"),
    ]
    for text, column in bad:
        with pytest.raises(DatasetError) as info:
            ColumnMap.from_toml(write(tmp_path, text, "m.toml"))
        assert info.value.column == column, text


def test_marker_column() -> None:
    log = read_csv_log(LOG, ColumnMap.from_toml(COLUMNS))
    assert log.marker is not None and set(log.marker) == {"MOVING", "CONTACT"}
    assert log.marker[0] == "MOVING" and log.marker[-1] == "CONTACT"
