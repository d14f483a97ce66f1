"""Run logs: a round trip keeps every value; a failed or interrupted write leaves nothing."""

from __future__ import annotations

import math
import os
from pathlib import Path

import h5py
import numpy as np
import pytest
from run_logs import assert_same_result, hand_made, real_run

from teachfit.core.errors import DatasetError
from teachfit.core.outcome import Outcome
from teachfit.demonstrations.dataset import Demonstration, write_dataset
from teachfit.execution import recording
from teachfit.execution.recording import (
    Episode,
    RunInfo,
    is_run_log,
    read_run_log,
    run_summary,
    write_run_log,
)
from teachfit.skills import peg_in_hole


def leftovers(folder: Path) -> list[Path]:
    return sorted(folder.glob(".*.tmp"))


def test_round_trip_keeps_every_value(tmp_path: Path) -> None:
    episodes, info = real_run()
    skill = peg_in_hole.build("adaptive")
    odd = Episode.of_skill(hand_made(), skill)
    path = write_run_log(tmp_path / "sub" / "run.h5", [*episodes, odd], info)
    assert is_run_log(path) and leftovers(path.parent) == []
    run = read_run_log(path)
    assert run.info == info and run.info.options == {"n": 20, "out": "peg2d"}
    assert run.info.entry_height == pytest.approx(info.entry_height) and run.version
    assert len(run.episodes) == 3
    for want, got in zip([*episodes, odd], run.episodes, strict=True):
        assert_same_result(want.result, got.result)
        assert got.name == want.name and dict(got.primitives) == dict(want.primitives)
    first = run.episodes[0]
    np.testing.assert_array_equal(first.start.as_array(), episodes[0].start.as_array())
    np.testing.assert_array_equal(first.planned.pos, episodes[0].planned.pos)
    assert first.planned.t.size == 20
    # the engine logs the commanded orientation beside the commanded position
    np.testing.assert_allclose(first.result.log.setpoint_quat[0], episodes[0].start.quat)
    got = run.episodes[2]
    assert got.start is None and got.planned is None
    assert got.result.detected is None and got.result.ground_truth_inserted is None
    assert got.result.log.node.tolist() == [0, 0, 1, -1, -1]
    assert set(got.primitives) == {n.name for n in skill.nodes} | {skill.recovery.name}
    assert all(got.primitives.values())  # what each node's primitive does, in words


def test_summary_rows(tmp_path: Path) -> None:
    episodes, info = real_run()
    run = read_run_log(write_run_log(tmp_path / "run.h5", episodes, info))
    into, away = run_summary(run)
    assert into["outcome"] == "success" and into["time_to_success"] > 0
    assert away["outcome"] == Outcome.TIMEOUT.value and math.isnan(away["time_to_success"])
    # depth below the nominal entry: in the hole after success, on the surface otherwise
    assert into["final_depth"] > 0.002 and abs(away["final_depth"]) < 0.001
    assert into["max_force"] == pytest.approx(episodes[0].result.peak_force)
    assert into["nodes"] == "follow" and into["duration"] == episodes[0].result.t_end


def test_a_failed_write_leaves_no_file_and_no_temp(tmp_path: Path, monkeypatch) -> None:
    episodes, info = real_run()
    target = tmp_path / "run.h5"
    calls = []

    def interrupted(group, ep) -> None:
        calls.append(ep)
        if len(calls) == 2:
            raise KeyboardInterrupt  # Ctrl-C in the middle of the file
        write(group, ep)

    write = recording.write_episode
    monkeypatch.setattr(recording, "write_episode", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_run_log(target, episodes, info)
    assert not target.exists() and leftovers(tmp_path) == []
    # an older run log is kept whole when its replacement fails
    monkeypatch.setattr(recording, "write_episode", write)
    write_run_log(target, episodes[:1], info)
    calls.clear()
    monkeypatch.setattr(recording, "write_episode", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_run_log(target, episodes, info)
    assert len(read_run_log(target).episodes) == 1 and leftovers(tmp_path) == []


def test_bad_targets_and_items_are_refused_before_writing(tmp_path: Path) -> None:
    episodes, info = real_run()
    t = np.linspace(0, 1, 5)
    quat = np.tile([1.0, 0, 0, 0], (5, 1))
    demo = Demonstration(t, np.zeros((5, 3)), quat, None, task="peg2d", source="synthetic")
    demos = write_dataset(tmp_path / "demos.h5", [demo])
    before = demos.read_bytes()
    with pytest.raises(DatasetError, match="not a run log"):
        write_run_log(demos, episodes, info)
    assert demos.read_bytes() == before  # a demonstration file is never replaced
    with pytest.raises(DatasetError, match="folder"):
        write_run_log(tmp_path, episodes, info)
    with pytest.raises(DatasetError, match="episode 1 is a str"):
        write_run_log(tmp_path / "run.h5", [episodes[0], "oops"], info)
    assert not (tmp_path / "run.h5").exists() and leftovers(tmp_path) == []


def test_reading_bad_files_names_them(tmp_path: Path) -> None:
    episodes, info = real_run()
    with pytest.raises(DatasetError, match="no such file"):
        read_run_log(tmp_path / "missing.h5")
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f.attrs["format"] = "teachfit-demos"
    assert not is_run_log(other)
    with pytest.raises(DatasetError, match=f"file {other}: not a teachfit run log"):
        read_run_log(other)
    damaged = write_run_log(tmp_path / "run.h5", episodes, info)
    with h5py.File(damaged, "r+") as f:
        del f["episodes/001/wrench"]
    with pytest.raises(DatasetError, match="/episodes/001 has no dataset 'wrench'"):
        read_run_log(damaged)
    with h5py.File(damaged, "r+") as f:
        f.attrs["format_version"] = 9
    with pytest.raises(DatasetError, match="format_version 9"):
        read_run_log(damaged)


def test_run_info_here_is_json_safe() -> None:
    info = RunInfo.here("assemble", "tenon", "fr3", 5, "rrt", {"out": Path("a/b.h5"), "n": 3})
    assert info.options == {"out": "a/b.h5", "n": 3}
    assert info.task == "tenon" and math.isnan(info.entry_height) and info.command


def _replace(name: str, value):
    def edit(f: h5py.File) -> None:
        del f[name]
        f[name] = value

    return edit


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (_replace("episodes/000", np.zeros(3)), "/episodes/000 is a dataset, not a group"),
        (_replace("episodes", np.zeros(3)), "/episodes is a dataset, not a group"),
        (_replace("episodes/000/visits", np.zeros(3)), "/visits is a dataset, not a group"),
        (_replace("episodes/000/pos", h5py.ExternalLink("/etc/x.h5", "/")),
         "/episodes/000/pos is an external link to /etc/x.h5:/"),
        (_replace("episodes/000/t", h5py.SoftLink("/episodes/000/t")), "too many links"),
        (_replace("episodes/000/visits/node", np.zeros(2)), "/node holds float64 values, not text"),
        (lambda f: f["episodes/000"].__delitem__("t") or f["episodes/000"].create_dataset(
            "t", shape=(400_000_000,), dtype="f8", chunks=(1 << 20,), compression="gzip"),
         r"/episodes/000/t declares \(400000000,\) values"),
        (lambda f: f["episodes/000"].attrs.__setitem__("outcome", 7),
         "attribute 'outcome' is 7 \\(int64\\), not a text string"),
        (lambda f: f.attrs.__setitem__("info", '{"kind": "search", "task": 7}'),
         "attribute 'info': task is 7, not a str"),
        (lambda f: f.attrs.__setitem__("info", "[1, 2]"), "'info' is not a run's description"),
        (lambda f: f.attrs.__setitem__("info", '{"kind": "x"}'), "'info' is incomplete"),
        (lambda f: f.attrs.__setitem__("format_version", [1]), r"format_version \[1\]"),
    ],
)  # fmt: skip
def test_crafted_run_logs_are_refused_before_reading(tmp_path: Path, edit, match: str) -> None:
    info = RunInfo("search", "peg2d", "floating", 0, "straight")
    path = write_run_log(tmp_path / "run.h5", [hand_made()], info)
    with h5py.File(path, "r+") as f:
        edit(f)
    with pytest.raises(DatasetError, match=match) as err:
        read_run_log(path)
    assert err.value.path == str(path) and "\n" not in str(err.value)


def test_a_run_log_keeps_the_umask(tmp_path: Path) -> None:
    info = RunInfo("search", "peg2d", "floating", 0, "straight")
    old = os.umask(0o077)
    try:
        path = write_run_log(tmp_path / "run.h5", [hand_made()], info)
    finally:
        os.umask(old)
    assert path.stat().st_mode & 0o777 == 0o600
