"""A misuse walk of ``teachfit demo import``: CSV dialects and limits, and damaged ROS bags.

Every bad input is refused with exit status 2 in one line that starts with ``error:`` and names
the input, with no traceback, and nothing is written anywhere (not the output, not a temporary
file, not a folder). The good variants of the same log (a BOM, CR or CRLF line ends, quoted
cells, another delimiter with its map, each bag format) are imported into the named output and
nothing else.
"""

from __future__ import annotations

import gzip
import shutil
from pathlib import Path

import numpy as np
import pytest
from panda_logs import panda_log, write_bag, write_log, write_map
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.demonstrations.csv_table import MAX_LINE_CHARS

runner = CliRunner()
BAG_TOPICS = ["--pose-topic", "/tcp_pose", "--wrench-topic", "/ft_sensor"]


def _edit(lines: list[str], row: int, column: int, value: str) -> str:
    """The log text with the cell at (1-based row, column index) replaced."""
    out = list(lines)
    cells = out[row - 1].split(",")
    cells[column] = value
    out[row - 1] = ",".join(cells)
    return "\n".join(out) + "\n"


def _csv_inputs(d: Path) -> dict[str, bytes | str]:
    """File name -> content of each bad CSV log (read with the map ``log.toml``)."""
    text = write_log(d / "log.csv", panda_log("search")).read_text()
    lines = text.splitlines()
    swapped = list(lines)
    swapped[40], swapped[41] = swapped[41], swapped[40]
    return {
        "huge_cell.csv": _edit(lines, 6, 13, '"' + "x" * 200_000 + '"'),
        "long_number.csv": _edit(lines, 6, 3, "1" * (MAX_LINE_CHARS + 1)),
        "unclosed_quote.csv": _edit(lines, 6, 0, '"' + lines[5].split(",")[0]),
        "unclosed_at_end.csv": _edit(lines, len(lines), 13, '"0.1'),
        "no_line_ends.csv": "1.0," * 1_000_000,
        "nul.csv": text.encode()[:300] + b"\x00" + text.encode()[300:],
        "utf16.csv": text.encode("utf-16"),
        "utf16le.csv": text.encode("utf-16-le"),
        "latin1.csv": text.encode()[:900] + "é".encode("latin-1") + text.encode()[900:],
        "log.csv.gz.csv": gzip.compress(text.encode()),
        "junk.csv": np.random.default_rng(0).integers(0, 256, 4096, dtype=np.uint8).tobytes(),
        "extra_cells.csv": _edit(lines, 9, 13, "0.1,7"),
        "short_row.csv": "\n".join([*lines[:8], ",".join(lines[8].split(",")[:6]), *lines[9:]]),
        "semicolons.csv": text.replace(",", ";"),
        "tabs.csv": text.replace(",", "\t"),
        "not_a_number.csv": _edit(lines, 12, 2, "0.45m"),
        "words.csv": _edit(lines, 12, 2, "abc" * 1000),
        "nan.csv": _edit(lines, 12, 2, "nan"),
        "inf.csv": _edit(lines, 12, 8, "-inf"),
        "backwards.csv": "\n".join(swapped) + "\n",
        "repeated_time.csv": _edit(lines, 30, 0, lines[28].split(",")[0]),
        "empty.csv": "",
        "header_only.csv": lines[0] + "\n",
        "blank_lines.csv": "\n\n\n",
    }


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("imports")
    for name, content in _csv_inputs(d).items():
        if isinstance(content, bytes):
            (d / name).write_bytes(content)
        else:
            (d / name).write_text(content)
    write_map(d / "log.toml")
    write_map(d / "semi.toml", delimiter=";")
    write_map(d / "dot.toml", delimiter=".")
    text = (d / "log.csv").read_text()
    (d / "comma_decimals.csv").write_text(text.replace(",", ";").replace(".", ","))
    write_bag(d / "good.bag")
    write_bag(d / "good_db3", storage="sqlite3")
    write_bag(d / "good_mcap", storage="mcap")
    bag = (d / "good.bag").read_bytes()
    (d / "truncated.bag").write_bytes(bag[: len(bag) // 2])
    (d / "header_only.bag").write_bytes(bag[:13])
    (d / "empty.bag").write_bytes(b"")
    junk = np.random.default_rng(1).integers(0, 256, 8192, dtype=np.uint8).tobytes()
    for name in ("junk.bag", "junk.db3", "junk.mcap"):
        (d / name).write_bytes(junk)
    mcap = shutil.copytree(d / "good_mcap", d / "truncated_mcap")
    (part,) = mcap.glob("*.mcap")
    part.write_bytes(part.read_bytes()[: part.stat().st_size // 2])
    db3 = shutil.copytree(d / "good_db3", d / "damaged_db3")
    (part,) = db3.glob("*.db3")
    data = bytearray(part.read_bytes())
    data[len(data) // 3 :] = bytes(len(data) - len(data) // 3)
    part.write_bytes(bytes(data))
    shutil.copytree(d / "good_db3", d / "no_metadata")
    (d / "no_metadata" / "metadata.yaml").unlink()
    shutil.copytree(d / "good_db3", d / "bad_metadata")
    (d / "bad_metadata" / "metadata.yaml").write_text("rosbag2_bagfile_information: [\n  x: {\n")
    (d / "not_a_bag").mkdir()
    return d


def _files(root: Path) -> dict[str, int]:
    return {str(p.relative_to(root)): p.stat().st_size for p in root.rglob("*") if p.is_file()}


BAD_CSV = [
    ("huge_cell.csv", "longer than 65536 characters"),
    ("long_number.csv", "longer than 65536 characters"),
    ("unclosed_quote.csv", "row 6: a quoted cell runs past the end of its line"),
    ("unclosed_at_end.csv", "row 501: a quoted cell runs past the end of its line"),
    ("no_line_ends.csv", "row 1: the line is longer than"),
    ("nul.csv", "NUL byte"),
    ("utf16.csv", "UTF-16 text: save it as UTF-8"),
    ("utf16le.csv", "NUL byte"),
    ("latin1.csv", "not UTF-8 text (invalid continuation byte at byte 900)"),
    ("log.csv.gz.csv", "a gzip file: decompress it first"),
    ("junk.csv", "not UTF-8 text"),
    ("extra_cells.csv", "row 9: the row has 15 cells, the header names 14"),
    ("short_row.csv", "row 9, column 'q2': line has only 6 cells"),
    ("semicolons.csv", "is the delimiter ';'? set delimiter = \";\""),
    ("tabs.csv", 'set delimiter = "\\t"'),
    ("not_a_number.csv", "row 12, column 'y': not a number: '0.45m'"),
    ("words.csv", "(3000 characters)"),
    ("nan.csv", "row 12, column 'y': non-finite value nan"),
    ("inf.csv", "row 12, column 'fx': non-finite value -inf"),
    ("backwards.csv", "row 42, column 't_ms': time not strictly increasing"),
    ("repeated_time.csv", "row 30, column 't_ms': time not strictly increasing"),
    ("empty.csv", "empty file, expected a header line"),
    ("header_only.csv", "0 data rows, need at least 2"),
    ("blank_lines.csv", "empty file, expected a header line"),
]


def _refused(inputs: Path, argv: list[str], *needles: str) -> str:
    """Run ``demo import`` with ``argv`` in ``inputs``; assert a clean refusal, nothing written."""
    before = _files(inputs)
    out_dir = inputs / f"out{len(before)}-{abs(hash(tuple(argv)))}"
    res = runner.invoke(app, ["demo", "import", *argv, "--out", str(out_dir / "demos.h5")])
    out = res.output.strip()
    assert res.exit_code == 2, out
    assert res.exception is None or isinstance(res.exception, SystemExit), repr(res.exception)
    assert "Traceback" not in out and len(out.splitlines()) == 1 and out.startswith("error: ")
    assert len(out) < 600, out
    for needle in needles:
        assert needle in out, (needle, out)
    assert _files(inputs) == before and not out_dir.exists()
    return out


@pytest.mark.parametrize(("name", "needle"), BAD_CSV)
def test_bad_csv_is_refused_in_one_line(
    inputs: Path, monkeypatch: pytest.MonkeyPatch, name: str, needle: str
) -> None:
    monkeypatch.chdir(inputs)
    _refused(inputs, ["--task", "peg2d", name, "--columns", "log.toml"], f"file {name}", needle)


@pytest.mark.parametrize(
    ("argv", "needles"),
    [
        (["log.csv", "--columns", "dot.toml"], ["file dot.toml", "cannot separate cells"]),
        (
            ["comma_decimals.csv", "--columns", "semi.toml"],
            ["file comma_decimals.csv, row 2, column 't_ms'", "(a decimal comma"],
        ),
        (["log.csv", "--columns", "missing.toml"], ["file missing.toml: no such column map"]),
        (["log.csv", "--columns", "log.csv"], ["file log.csv: invalid TOML"]),
        (["not_a_bag", *BAG_TOPICS], ["file not_a_bag: cannot read as a ROS bag"]),
    ],
)
def test_bad_maps_and_folders(
    inputs: Path, monkeypatch: pytest.MonkeyPatch, argv: list[str], needles: list[str]
) -> None:
    monkeypatch.chdir(inputs)
    _refused(inputs, ["--task", "peg2d", *argv], *needles)


def test_task_is_required(inputs: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(inputs)
    out = _refused(inputs, ["log.csv", "--columns", "log.toml"], "give --task: which task log.csv")
    assert "peg2d" in out


@pytest.mark.parametrize(
    ("bag", "extra", "needle"),
    [
        ("truncated.bag", [], "cannot read as a ROS bag"),
        ("header_only.bag", [], "cannot read as a ROS bag"),
        ("empty.bag", [], "cannot read as a ROS bag"),
        ("junk.bag", [], "cannot read as a ROS bag"),
        ("junk.db3", [], "cannot read as a ROS bag"),
        ("junk.mcap", [], "cannot read as a ROS bag"),
        ("truncated_mcap", [], "cannot read as a ROS bag"),
        ("damaged_db3", [], "cannot read as a ROS bag"),
        ("no_metadata", [], "cannot read as a ROS bag"),
        ("bad_metadata", [], "cannot read as a ROS bag"),
        ("missing.bag", [], "no such file or folder"),
        ("good.bag", ["--pose-topic", "/nope"], "no topic '/nope' in the bag (topics: /tcp_pose"),
        ("good_db3", ["--wrench-topic", "/nope"], "no topic '/nope'"),
        ("good_mcap", ["--wrench-topic", "/tcp_pose"], "topic '/tcp_pose' carries"),
        ("good.bag", ["--pose-topic", "/ft_sensor"], "expected one of geometry_msgs/msg/Pose"),
        ("good.bag", ["--child-frame", "tool"], "has no child frame: drop --child-frame"),
        ("good.bag", ["--wrench-sign", "2"], "--wrench-sign must be +1 or -1"),
    ],
)
def test_bad_bags_are_refused_in_one_line(
    inputs: Path, monkeypatch: pytest.MonkeyPatch, bag: str, extra: list[str], needle: str
) -> None:
    monkeypatch.chdir(inputs)
    topics = dict(zip(BAG_TOPICS[::2], BAG_TOPICS[1::2], strict=True))
    topics.update(dict(zip(extra[::2], extra[1::2], strict=True)))
    argv = [a for pair in topics.items() for a in pair]
    _refused(inputs, ["--task", "peg2d", bag, *argv], needle, bag)


def test_bag_without_a_pose_topic(inputs: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(inputs)
    _refused(inputs, ["--task", "peg2d", "good.bag"], "good.bag is a bag: give --pose-topic")


@pytest.mark.parametrize(
    ("name", "content", "argv"),
    [
        ("bom.csv", lambda t: b"\xef\xbb\xbf" + t.encode(), ["--columns", "log.toml"]),
        ("crlf.csv", lambda t: t.replace("\n", "\r\n").encode(), ["--columns", "log.toml"]),
        ("cr.csv", lambda t: t.replace("\n", "\r").encode(), ["--columns", "log.toml"]),
        ("semi_ok.csv", lambda t: t.replace(",", ";").encode(), ["--columns", "semi.toml"]),
        (
            "quoted.csv",
            lambda t: "\n".join(
                ",".join(f'"{c}"' for c in line.split(",")) for line in t.splitlines()
            ).encode(),
            ["--columns", "log.toml"],
        ),
        ("good.bag", None, BAG_TOPICS),
        ("good_db3", None, BAG_TOPICS),
        ("good_mcap", None, BAG_TOPICS),
    ],
)
def test_good_variants_write_only_the_named_output(
    inputs: Path, monkeypatch: pytest.MonkeyPatch, name: str, content, argv: list[str]
) -> None:
    monkeypatch.chdir(inputs)
    if content is not None:
        (inputs / name).write_bytes(content((inputs / "log.csv").read_text()))
    before = _files(inputs)
    out = f"o_{name}/demos.h5"
    res = runner.invoke(app, ["demo", "import", "--task", "peg2d", name, *argv, "--out", out])
    assert res.exit_code == 0, res.output
    added = set(_files(inputs)) - set(before)
    assert added == {out}
    assert all(_files(inputs)[k] == size for k, size in before.items())


@pytest.mark.parametrize("flag", ["--overwrite", "--append"])
def test_output_that_is_an_input_is_refused(
    inputs: Path, monkeypatch: pytest.MonkeyPatch, flag: str
) -> None:
    monkeypatch.chdir(inputs)
    before = _files(inputs)
    for out, named in (("log.csv", "log.csv"), ("log.toml", "log.toml"), ("good_db3/x.h5", "")):
        source = "good_db3" if named == "" else "log.csv"
        extra = BAG_TOPICS if named == "" else ["--columns", "log.toml"]
        argv = ["demo", "import", "--task", "peg2d", source, *extra, "--out", out, flag]
        res = runner.invoke(app, argv)
        assert res.exit_code == 2 and res.output.startswith(f"error: --out {out} is "), res.output
        assert "the input" in res.output and len(res.output.strip().splitlines()) == 1
    assert _files(inputs) == before
