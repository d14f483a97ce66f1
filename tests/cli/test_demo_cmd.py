"""``teachfit demo import`` / ``demo export``: each import mistake made on purpose is one clear
error (exit code 2, no traceback, nothing written) naming the file and the fix."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
from panda_logs import panda_log, write_bag, write_log, write_map
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.demonstrations.dataset import read_dataset

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()
#: ``demo import`` of the example log (``--out`` to add)
EXAMPLE_IMPORT = [
    "demo",
    "import",
    "--task",
    "peg2d",
    EXAMPLES / "robot_log.csv",
    "--columns",
    EXAMPLES / "columns.toml",
]


def invoke(*args: object):
    return runner.invoke(app, [str(a) for a in args])


def import_log(tmp_path: Path, kind: str = "search", log=None, cmap=None, *extra: object):
    csv = write_log(tmp_path / f"{kind}.csv", panda_log(kind), **(log or {}))
    the_map = write_map(tmp_path / f"{kind}.toml", **(cmap or {}))
    out = tmp_path / "demos.h5"
    res = invoke(
        "demo", "import", "--task", "peg2d", csv, "--columns", the_map, "--out", out, *extra
    )
    return res, csv, the_map, out


def bag_import(bag: Path, *extra: object) -> list[object]:
    """``demo import`` of ``bag``'s ``/tcp_pose`` topic as peg2d, then ``extra``."""
    return ["demo", "import", "--task", "peg2d", bag, "--pose-topic", "/tcp_pose", *extra]


def squeeze(text: str) -> str:
    """``text`` without whitespace: rich wraps long lines (also inside long paths)."""
    return "".join(text.split())


def shows(res, needle: str) -> bool:
    """Whether the command printed ``needle`` (whitespace ignored)."""
    return squeeze(needle) in squeeze(res.output)


def assert_refused(res, out: Path, *needles: str) -> str:
    text = squeeze(res.output)
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.output and res.output.count("error:") == 1
    for needle in needles:
        assert squeeze(needle) in text, (needle, res.output)
    assert not out.exists() and not list(out.parent.glob(".*.tmp*"))  # nothing half-written
    return text


def test_correct_import_prints_a_table(tmp_path: Path) -> None:
    res, _, _, out = import_log(tmp_path)
    assert res.exit_code == 0, res.output
    assert shows(res, "search") and shows(res, "24.95") and shows(res, "500")
    assert shows(res, "20.0") and shows(res, "not the simulation world")
    (demo,) = read_dataset(out)
    assert demo.frame == "panda_link0" and demo.meta["source_format"] == "csv"


def test_no_time_column(tmp_path: Path) -> None:
    res, _, the_map, out = import_log(tmp_path, log={"time_column": None}, cmap={"time": None})
    assert_refused(res, out, f"file {the_map}", "rate_hz", "--rate")
    res, *_ = import_log(tmp_path, "search", {"time_column": None}, {"time": None}, "--rate", 20)
    assert res.exit_code == 0, res.output
    assert read_dataset(out)[0].rate_hz == pytest.approx(20.0)


def test_quaternion_order(tmp_path: Path) -> None:
    res, csv, the_map, out = import_log(tmp_path, cmap={"quat_order": None})
    assert_refused(
        res,
        out,
        f"file {csv}",
        "tool axis tilts up to 180 deg",
        f'set quat_order = "x,y,z,w" in {the_map}',
    )


def test_milliseconds(tmp_path: Path) -> None:
    res, csv, the_map, out = import_log(tmp_path, cmap={"time_scale": 1.0})
    assert_refused(
        res,
        out,
        f"file {csv}",
        "sampling rate 0.02 Hz",
        f"if it is in ms, set time_scale = 0.001 in {the_map}",
    )


def test_wrench_sign(tmp_path: Path) -> None:
    res, csv, the_map, out = import_log(tmp_path, log={"robot_wrench": True})
    assert_refused(
        res,
        out,
        f"file {csv}",
        "points down",
        f"flip wrench_sign, set wrench_sign = -1 in {the_map}",
        "--accept wrench_sign",
    )
    res, *_ = import_log(
        tmp_path, "search", {"robot_wrench": True}, None, "--accept", "wrench_sign"
    )
    assert res.exit_code == 0 and shows(res, "accepted implausible wrench_sign")


def test_long_log_and_segmenting(tmp_path: Path) -> None:
    res, csv, _, out = import_log(tmp_path, "tasks")
    assert_refused(res, out, f"file {csv}", "284.9 s long", "--segment contact")
    res, *_ = import_log(tmp_path, "tasks", None, None, "--segment", "contact")
    assert res.exit_code == 0, res.output
    for k in range(3):
        assert shows(res, f"tasks-0{k}")
    assert res.output.count("49.95") == 3 and shows(res, "imported 3 demonstration(s)")
    assert len(read_dataset(out)) == 3
    res, *_ = import_log(tmp_path, "tasks", None, None, "--segment", "tides")
    assert_refused(res, out.with_name("none.h5"), "segment by one of")


def test_accept_implausible(tmp_path: Path) -> None:
    res, _, _, out = import_log(tmp_path, "tasks", None, None, "--accept-implausible")
    assert res.exit_code == 0, res.output
    assert shows(res, "accepted implausible duration")
    assert shows(res, "accepted implausible extent")
    res, _, _, out = import_log(tmp_path, "tasks", None, None, "--accept", "speling")
    assert shows(res, "unknown check 'speling'") and res.exit_code == 2


def test_truncated_last_line(tmp_path: Path) -> None:
    csv = write_log(tmp_path / "log.csv", panda_log("search"))
    csv.write_text(csv.read_text()[:-9])  # cut inside the last number, no newline at the end
    the_map = write_map(tmp_path / "log.toml")
    res = invoke(
        "demo", "import", "--task", "peg2d", csv, "--columns", the_map, "--out", tmp_path / "d.h5"
    )
    assert res.exit_code == 0, res.output
    assert shows(res, f"file {csv}, row 501: the last line is cut short")
    assert read_dataset(tmp_path / "d.h5")[0].n_samples == 499


def test_out_into_a_missing_folder_is_created(tmp_path: Path) -> None:
    out = tmp_path / "new" / "deeper" / "demos.h5"
    args = EXAMPLE_IMPORT
    res = invoke(*args, "--out", out)
    assert res.exit_code == 0, res.output
    assert h5py.is_hdf5(out)
    res = invoke(*args, "--out", tmp_path)
    assert_refused(res, tmp_path / "absent.h5", f"--out {tmp_path} is a folder")


def test_bag_import(tmp_path: Path) -> None:
    bag = tmp_path / "run.bag"
    write_bag(bag)
    out = tmp_path / "demos.h5"
    res = invoke("demo", "import", "--task", "peg2d", bag, "--out", out)
    assert_refused(res, out, "is a bag: give --pose-topic")
    res = invoke("demo", "import", bag, "--pose-topic", "/tcp_pose", "--out", out)
    assert_refused(res, out, f"give --task: which task {bag} demonstrates (one of ")
    res = invoke(*bag_import(bag, "--wrench-topic", "/ft_sensor", "--out", out))
    assert res.exit_code == 0, res.output
    assert read_dataset(out)[0].meta["pose_topic"] == "/tcp_pose"


def test_export_round_trip(tmp_path: Path) -> None:
    h5 = tmp_path / "demos.h5"
    args = EXAMPLE_IMPORT
    assert invoke(*args, "--out", h5).exit_code == 0
    out, the_map = tmp_path / "out" / "x.csv", tmp_path / "out" / "x.toml"
    res = invoke("demo", "export", f"{h5}:0", "--out", out, "--columns", the_map)
    assert res.exit_code == 0, res.output
    res = invoke("demo", "import", "--task", "peg2d", out, "--columns", the_map, "--out", h5)
    assert res.exit_code == 2 and shows(res, "pass --append to add to it")  # no silent pooling
    assert (
        invoke(
            "demo", "import", "--task", "peg2d", out, "--columns", the_map, "--out", h5, "--append"
        ).exit_code
        == 0
    )
    first, again = read_dataset(h5)
    for label in ("t", "pos", "quat", "wrench"):
        np.testing.assert_array_equal(getattr(again, label), getattr(first, label))
    res = invoke("demo", "export", f"{h5}:7", "--out", out)
    assert res.exit_code == 2 and shows(res, "index 7 out of range: the file holds 2 demos")
    res = invoke("demo", "export", f"{h5}:0", "--out", out)
    assert res.exit_code == 2 and shows(res, "file exists")


def test_transform_option_and_options_for_the_other_kind(tmp_path: Path) -> None:
    res, *_, out = import_log(
        tmp_path, "search", None, None, "--transform", "world:0,0,-0.2,1,0,0,0"
    )
    assert res.exit_code == 0, res.output
    assert not shows(res, "not the simulation world")
    (demo,) = read_dataset(out)
    assert demo.frame == "world" and demo.meta["source2frame"] == [0, 0, -0.2, 1, 0, 0, 0]
    assert demo.pos[0, 2] == pytest.approx(0.10, abs=1e-6)
    res, *_ = import_log(tmp_path, "search", None, None, "--transform", "world:0,0")
    assert_refused(res, tmp_path / "none.h5", "'FRAME:x,y,z,qw,qx,qy,qz'")
    res, *_ = import_log(tmp_path, "search", None, None, "--pose-topic", "/tcp_pose")
    assert_refused(res, tmp_path / "none.h5", "--pose-topic is for ROS bags")
    bag = tmp_path / "run.bag"
    write_bag(bag)
    res = invoke(*bag_import(bag, "--rate", 20, "--out", out))
    assert_refused(res, tmp_path / "none.h5", "drop --rate")
