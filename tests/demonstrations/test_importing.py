"""Each way a real log is imported wrongly, made on purpose on generated Panda-like logs, gives
one clear message naming the file and the fix; done right, the data comes through intact."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from panda_logs import panda_log, tilted_between_tasks, write_log

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.csv_import import ColumnMap, import_csv, read_csv_log
from teachfit.demonstrations.frames import FrameTransform
from teachfit.demonstrations.importing import ImportOptions, build_demos
from teachfit.demonstrations.segment import Segmenter
from teachfit.models.search_data import yaw_relative


def imported(csv: Path, cmap: Path, **options) -> list:
    log = read_csv_log(csv, ColumnMap.from_toml(cmap))
    opts = ImportOptions(**{"transform": ColumnMap.from_toml(cmap).transform, **options})
    return list(build_demos(log, task="peg2d", name="run", options=opts).demos)


def refused(csv: Path, cmap: Path, **options) -> str:
    with pytest.raises(DatasetError) as info:
        imported(csv, cmap, **options)
    message = str(info.value)
    assert message.startswith(f"file {csv}: ") and "\n" not in message
    return message


def test_a_correct_map_imports_the_log_intact(make_log) -> None:
    csv, cmap = make_log("search")
    (demo,) = imported(csv, cmap)
    truth = panda_log("search")
    assert demo.frame == "panda_link0" and demo.meta["source_frame"] == "panda_link0"
    assert demo.rate_hz == pytest.approx(20.0) and demo.duration == pytest.approx(24.95)
    np.testing.assert_allclose(demo.t, truth["t"], atol=1e-9)
    np.testing.assert_allclose(demo.pos, truth["pos"], atol=1e-6)
    np.testing.assert_allclose(np.abs(np.sum(demo.quat * truth["quat"], axis=1)), 1.0, atol=1e-5)
    np.testing.assert_allclose(demo.wrench, truth["wrench"], atol=1e-3)
    yaw = np.ptp(yaw_relative(demo.quat))
    assert np.degrees(yaw) == pytest.approx(278.0 * 499 / 500, abs=1.0)


def test_no_time_column_with_a_rate(make_log) -> None:
    csv, cmap = make_log("search", log={"time_column": None}, cmap={"time": None, "rate_hz": 20.0})
    (demo,) = imported(csv, cmap)
    assert demo.rate_hz == pytest.approx(20.0) and demo.n_samples == 500


def test_quaternion_in_the_wrong_order(make_log) -> None:
    csv, cmap = make_log("search", cmap={"quat_order": None})  # x,y,z,w read as w,x,y,z
    message = refused(csv, cmap)
    assert "implausible orientation: the tool axis tilts up to 180 deg" in message
    assert f'set quat_order = "x,y,z,w" in {cmap}' in message


def test_orientation_jump(make_log, tmp_path: Path) -> None:
    csv, cmap = make_log("search")
    lines = csv.read_text().splitlines()
    for i in range(200, 501):  # the q1 (y) and q2 (z) columns swapped for the rest of the log
        cells = lines[i].split(",")
        cells[5], cells[6] = cells[6], cells[5]
        lines[i] = ",".join(cells)
    csv.write_text("\n".join(lines) + "\n")
    message = refused(csv, cmap)
    assert "orientation jumps by" in message and "between rows 200 and 201" in message
    assert "check the quaternion columns" in message
    assert "a column swapped or missing part way" in message and "--segment" not in message


def test_milliseconds_read_as_seconds(make_log) -> None:
    csv, cmap = make_log("search", cmap={"time_scale": 1.0})
    message = refused(csv, cmap)
    assert "implausible rate: sampling rate 0.02 Hz" in message
    assert f"steps by 50 units: if it is in ms, set time_scale = 0.001 in {cmap}" in message
    assert "also implausible" not in message  # the first cause only, no cascade
    demos = imported(csv, cmap, accept=frozenset({"all"}))  # accepting is possible, and honest
    assert demos[0].duration == pytest.approx(24950.0)


def test_robot_wrench_stored_as_the_environments(make_log) -> None:
    csv, cmap = make_log("search", log={"robot_wrench": True})
    message = refused(csv, cmap)
    assert "force on the tool points down (median fz = -8.0 N in 'panda_link0')" in message
    assert f"the robot applies: flip wrench_sign, set wrench_sign = -1 in {cmap}" in message
    (demo,) = imported(csv, cmap, accept=frozenset({"wrench_sign"}))
    assert np.median(demo.wrench[-100:, 2]) < 0  # accepted as it is: nothing silently flipped


def test_example_map_sign_on_an_environment_wrench_log(make_log) -> None:
    csv, cmap = make_log("search", cmap={"wrench_sign": -1})
    message = refused(csv, cmap)
    assert f"-1 negates it: flip wrench_sign, set wrench_sign = 1 in {cmap}" in (message)


def test_base_frame_is_transformed_or_noted(make_log) -> None:
    csv, cmap = make_log("search")
    log = read_csv_log(csv, ColumnMap.from_toml(cmap))
    result = build_demos(log, task="peg2d", name="run", options=ImportOptions())
    assert any("not the simulation world" in n for n in result.notes)
    base2world = FrameTransform(to="world", pos=(-0.45, 0.10, -0.20), quat=(0.0, 0.0, 0.0, 1.0))
    result = build_demos(log, task="peg2d", name="run", options=ImportOptions(base2world))
    (demo,) = result.demos
    assert demo.frame == "world" and not any("simulation world" in n for n in result.notes)
    assert demo.meta["source2frame"] == [-0.45, 0.10, -0.20, 0.0, 0.0, 0.0, 1.0]
    # 180 deg about z: x and y flip, then the offset; forces rotate the same way
    np.testing.assert_allclose(demo.pos[0], [-0.45 - 0.45, 0.10 + 0.10, 0.30 - 0.20], atol=1e-6)
    np.testing.assert_allclose(demo.wrench[:, :3], log.wrench[:, :3] * [-1, -1, 1], atol=1e-12)
    anchored = build_demos(
        log, task="peg2d", name="run", options=ImportOptions(FrameTransform(first_pose=True))
    )
    (demo,) = anchored.demos
    assert demo.frame == "panda_link0_start"
    np.testing.assert_allclose(demo.pos[0], 0.0, atol=1e-15)
    np.testing.assert_allclose(demo.meta["source2frame"][:3], -log.pos[0])
    np.testing.assert_allclose(demo.quat, log.quat, atol=1e-5)  # only normalised


def test_map_transform_is_applied(make_log) -> None:
    csv, cmap = make_log("search")
    cmap.write_text('transform = "first-pose"\n' + cmap.read_text())
    (demo,) = imported(csv, cmap)
    assert demo.frame == "panda_link0_start" and np.all(demo.pos[0] == 0.0)
    text = cmap.read_text().replace('transform = "first-pose"\n', "")
    cmap.write_text(text + '[transform]\nto = "world"\npos = [0.0, 0.0, -0.2]\n')
    (demo,) = imported(csv, cmap)
    assert demo.frame == "world" and demo.pos[0, 2] == pytest.approx(0.10, abs=1e-6)


def test_several_tasks_in_one_log(make_log) -> None:
    csv, cmap = make_log("tasks")
    message = refused(csv, cmap)
    assert "implausible duration: 284.9 s long; one search demonstration lasts at most 120 s" in (
        message
    )
    assert "--segment contact, window or marker" in message and "also implausible: extent" in (
        message
    )


def test_segment_by_contact(make_log) -> None:
    csv, cmap = make_log("tasks")
    demos = imported(csv, cmap, segmenter=Segmenter("contact", force_on_n=5.0))
    assert [d.name for d in demos] == ["run-00", "run-01", "run-02"]
    for k, demo in enumerate(demos):
        start = 45.0 + 95.0 * k
        assert demo.meta["segment_start_s"] == pytest.approx(start, abs=0.1)
        assert demo.duration == pytest.approx(49.95, abs=0.1)
        assert np.ptp(demo.pos[:, :2], axis=0).max() < 0.03  # the 24 mm spiral, not the transfer
        assert np.all(np.linalg.norm(demo.wrench[:, :3], axis=1) > 2.5)  # above the off level


def test_orientation_is_checked_per_segment(make_log, tmp_path: Path) -> None:
    """A log whose tool tilts 62 deg between three tasks, at most 4 deg within each search."""
    _, cmap = make_log("tasks")
    csv = write_log(tmp_path / "tilted.csv", tilted_between_tasks(panda_log("tasks")))
    message = refused(csv, cmap, accept=frozenset({"duration", "extent"}))
    assert "implausible orientation: the tool axis tilts up to 62 deg" in message
    assert "read as w,x,y,z the track would pass, but the tool would point up" in message
    assert "the tool probably really turns, cut the log into demonstrations (--segment" in message
    assert f'if the order is wrong after all, set quat_order = "w,x,y,z" in {cmap}' in message
    demos = imported(csv, cmap, segmenter=Segmenter("contact", force_on_n=5.0))
    assert [d.name for d in demos] == ["run-00", "run-01", "run-02"]
    assert [d.meta["rate_hz"] for d in demos] == [20.0, 20.0, 20.0]


def test_wrong_order_is_named_per_segment(make_log) -> None:
    csv, cmap = make_log("search", cmap={"quat_order": None})  # x,y,z,w read as w,x,y,z
    message = refused(csv, cmap, segmenter=Segmenter("contact", force_on_n=5.0))
    assert message.startswith(f"file {csv}: demonstration run-00 (rows 102-501): implausible")
    assert "read as w,x,y,z" in message
    assert "the quaternion components are in x,y,z,w order" in message
    assert f'set quat_order = "x,y,z,w" in {cmap}' in message


def test_segment_pieces_still_checked(make_log) -> None:
    csv, cmap = make_log("tasks")
    message = refused(csv, cmap, segmenter=Segmenter("window", window_s=60.0))
    assert "demonstration run-00 (rows 2-1201): implausible extent: the tool covers 152 x 4 mm" in (
        message
    )


def test_nothing_found_to_segment(make_log) -> None:
    csv, cmap = make_log("tasks")
    message = refused(csv, cmap, segmenter=Segmenter("contact", force_on_n=50.0))
    assert "no contact phase above 50 N lasting at least 1 s: nothing to import" in message


def test_import_csv_applies_the_checks(make_log) -> None:
    csv, cmap = make_log("search", cmap={"time_scale": 1.0})
    with pytest.raises(DatasetError, match="implausible rate"):
        import_csv(csv, ColumnMap.from_toml(cmap), task="peg2d")
