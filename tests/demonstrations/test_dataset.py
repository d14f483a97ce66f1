"""Tests of the Demonstration value and the teachfit-demos HDF5 format."""

from __future__ import annotations

import json
import os
from pathlib import Path

import h5py
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from teachfit.core.errors import DatasetError
from teachfit.demonstrations import dataset as ds
from teachfit.demonstrations.dataset import (
    Demonstration,
    append_dataset,
    dataset_summary,
    read_dataset,
    read_demo,
    write_dataset,
)


def make_demo(
    seed: int = 0, n: int = 25, *, wrench: bool = True, name: str = "d", **kw: object
) -> Demonstration:
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.01, 0.03, n))
    pos = rng.normal(0.0, 0.1, (n, 3))
    xyzw = Rotation.from_rotvec(rng.normal(0.0, 0.5, (n, 3))).as_quat()
    quat = xyzw[:, [3, 0, 1, 2]]
    w = rng.normal(0.0, 5.0, (n, 6)) if wrench else None
    args: dict[str, object] = {"task": "peg2d", "source": "synthetic", "name": name}
    args.update(kw)
    return Demonstration(t=t, pos=pos, quat=quat, wrench=w, **args)  # type: ignore[arg-type]


def tmp_leftovers(directory: Path) -> list[Path]:
    return [p for p in directory.iterdir() if ".tmp" in p.name]


# ---------------------------------------------------------------- Demonstration validation


def test_valid_demo_is_read_only_normalised_copy() -> None:
    demo = make_demo()
    quat = np.array(demo.quat) * 1.0005  # within tolerance: accepted and normalised
    d2 = Demonstration(t=demo.t, pos=demo.pos, quat=quat, wrench=None, task="x", source="captured")
    np.testing.assert_allclose(np.linalg.norm(d2.quat, axis=1), 1.0, atol=1e-12)
    assert not d2.quat.flags.writeable and not d2.t.flags.writeable
    quat[0] = 7.0  # the caller's array is not shared
    assert np.all(np.abs(d2.quat) <= 1.0)
    with pytest.raises(ValueError):
        d2.pos[0, 0] = 1.0
    assert d2.n_samples == 25 and d2.wrench is None


@pytest.mark.parametrize(
    ("field", "row", "mutate"),
    [
        ("pos", 3, lambda a: a["pos"].__setitem__((3, 1), np.nan)),
        ("wrench", 5, lambda a: a["wrench"].__setitem__((5, 4), np.inf)),
        ("t", 7, lambda a: a["t"].__setitem__(7, np.nan)),
        ("quat", 2, lambda a: a["quat"].__setitem__((2, 0), -np.inf)),
        ("t", 4, lambda a: a["t"].__setitem__(4, a["t"][3])),
        ("t", 9, lambda a: a["t"].__setitem__(9, a["t"][8] - 0.5)),
        ("quat", 6, lambda a: a["quat"].__setitem__(6, a["quat"][6] * 1.01)),
        ("pos", None, lambda a: a.__setitem__("pos", a["pos"][:, :2])),
        ("quat", None, lambda a: a.__setitem__("quat", a["quat"][:-1])),
        ("wrench", None, lambda a: a.__setitem__("wrench", a["wrench"][:, :3])),
        ("t", None, lambda a: a.__setitem__("t", a["t"][:, None])),
    ],
)
def test_invalid_arrays_name_field_and_row(field: str, row: int | None, mutate) -> None:
    demo = make_demo()
    arrays = {k: np.array(getattr(demo, k)) for k in ("t", "pos", "quat", "wrench")}
    mutate(arrays)
    with pytest.raises(DatasetError) as info:
        Demonstration(**arrays, task="peg2d", source="synthetic")
    assert info.value.column == field
    assert info.value.row == row


def test_too_few_samples() -> None:
    with pytest.raises(DatasetError, match="at least 2") as info:
        Demonstration(
            t=[0.0], pos=[[0, 0, 0]], quat=[[1, 0, 0, 0]], wrench=None, task="a", source="synthetic"
        )
    assert info.value.column == "t"
    ok = Demonstration(
        t=[0.0, 1.0],
        pos=np.zeros((2, 3)),
        quat=[[1, 0, 0, 0]] * 2,
        wrench=None,
        task="a",
        source="synthetic",
    )
    assert ok.n_samples == ds.MIN_SAMPLES


@pytest.mark.parametrize(
    ("kw", "column"),
    [
        ({"source": "made-up"}, "source"),
        ({"task": ""}, "task"),
        ({"frame": ""}, "frame"),
        ({"meta": {"x": object()}}, "meta"),
        ({"meta": {"x": float("nan")}}, "meta"),
        ({"meta": {1: "a"}}, "meta"),
    ],
)
def test_invalid_labels(kw: dict, column: str) -> None:
    with pytest.raises(DatasetError) as info:
        make_demo(**kw)
    assert info.value.column == column


def test_properties() -> None:
    t = np.arange(11) * 0.1
    t[5] += 0.02  # one late sample does not move the median rate
    demo = Demonstration(
        t=t,
        pos=np.zeros((11, 3)),
        quat=np.tile([1.0, 0, 0, 0], (11, 1)),
        wrench=None,
        task="a",
        source="synthetic",
    )
    assert demo.duration == pytest.approx(1.0)
    assert demo.rate_hz == pytest.approx(10.0)
    np.testing.assert_allclose(demo.rotvec(), 0.0)
    assert demo.rotvec().shape == (11, 3)


# ---------------------------------------------------------------- geometry


def test_in_search_frame() -> None:
    demo = make_demo(seed=3, frame="world")
    s = demo.in_search_frame()
    assert s.frame == "search" and s.task == demo.task
    np.testing.assert_array_equal(s.pos[0], 0.0)
    np.testing.assert_array_equal(s.quat[0], [1.0, 0.0, 0.0, 0.0])
    # distances and relative rotations between samples are preserved
    d_orig = np.linalg.norm(demo.pos[:, None] - demo.pos[None], axis=-1)
    d_new = np.linalg.norm(s.pos[:, None] - s.pos[None], axis=-1)
    np.testing.assert_allclose(d_new, d_orig, atol=1e-12)
    r_orig, r_new = ds._rot(demo.quat), ds._rot(s.quat)
    rel_orig = (r_orig[:-1].inv() * r_orig[1:]).magnitude()
    rel_new = (r_new[:-1].inv() * r_new[1:]).magnitude()
    np.testing.assert_allclose(rel_new, rel_orig, atol=1e-9)
    # mapping back with the recorded origin gives the original poses and wrenches
    origin = np.array(s.meta["search2world"])
    r0 = ds._rot(origin[3:])
    np.testing.assert_allclose(r0.apply(np.array(s.pos)) + origin[:3], demo.pos, atol=1e-12)
    np.testing.assert_allclose((r0 * r_new).as_matrix(), r_orig.as_matrix(), atol=1e-12)
    np.testing.assert_allclose(r0.apply(np.array(s.wrench[:, :3])), demo.wrench[:, :3], atol=1e-12)
    np.testing.assert_allclose(r0.apply(np.array(s.wrench[:, 3:])), demo.wrench[:, 3:], atol=1e-12)
    assert not np.allclose(s.wrench, demo.wrench)  # it really was rotated
    assert make_demo(wrench=False).in_search_frame().wrench is None


def test_resampled() -> None:
    t = np.array([0.0, 0.5, 1.0])
    pos = np.array([[0.0, 0, 0], [1.0, 2.0, 0], [2.0, 2.0, 1.0]])
    quat = Rotation.from_euler("z", [[0.0], [0.5], [1.0]]).as_quat()[:, [3, 0, 1, 2]]
    wrench = np.outer([0.0, 1.0, 4.0], np.arange(1, 7))
    demo = Demonstration(t=t, pos=pos, quat=quat, wrench=wrench, task="a", source="synthetic")
    r = demo.resampled(4.0)
    np.testing.assert_allclose(r.t, [0.0, 0.25, 0.5, 0.75, 1.0])
    np.testing.assert_allclose(r.pos[1], [0.5, 1.0, 0.0])
    np.testing.assert_allclose(r.pos[3], [1.5, 2.0, 0.5])
    np.testing.assert_allclose(r.wrench[3], 2.5 * np.arange(1, 7))
    np.testing.assert_allclose(ds._rot(r.quat).as_euler("xyz")[:, 2], [0, 0.25, 0.5, 0.75, 1.0])
    assert np.all(r.quat[:, 0] > 0)  # same hemisphere as the input
    assert demo.resampled(3.0).t[-1] <= 1.0
    with pytest.raises(DatasetError):
        demo.resampled(0.0)


# ---------------------------------------------------------------- files


def test_round_trip(tmp_path: Path) -> None:
    demos = [
        make_demo(1, name="first", meta={"operator": "ana", "trial": 3, "ok": True, "k": 0.5}),
        make_demo(2, n=40, wrench=False, source="captured", frame="G", child_frame="peg"),
        make_demo(3, task="l-groove").in_search_frame(),
    ]
    path = write_dataset(tmp_path / "demos.h5", demos)
    back = read_dataset(path)
    assert back == demos
    assert back[1].wrench is None and back[1].frame == "G" and back[1].child_frame == "peg"
    assert back[0].meta == {"operator": "ana", "trial": 3, "ok": True, "k": 0.5}
    with h5py.File(path) as f:
        assert f.attrs["format"] == "teachfit-demos" and f.attrs["format_version"] == 1
        assert json.loads(f.attrs["units"])["pos"] == "m"
        assert sorted(f["demos"]) == ["000", "001", "002"]
        assert "wrench" not in f["demos/001"]
    assert read_demo(f"{path}:1") == demos[1]
    assert read_demo(path) == demos[0]
    assert read_demo(str(path)) == demos[0]
    rows = dataset_summary(path)
    assert [r["samples"] for r in rows] == [25, 40, 25]
    assert rows[0]["name"] == "first" and rows[2]["task"] == "l-groove"
    assert rows[1]["rate"] == pytest.approx(demos[1].rate_hz, rel=1e-5)  # shown rounded
    assert tmp_leftovers(tmp_path) == []


def test_read_demo_out_of_range(tmp_path: Path) -> None:
    path = write_dataset(tmp_path / "d.h5", [make_demo(1), make_demo(2)])
    for spec in (f"{path}:2", f"{path}:-1"):
        with pytest.raises(DatasetError, match="holds 2 demos") as info:
            read_demo(spec)
        assert info.value.path == str(path)


def test_overwrite_refused(tmp_path: Path) -> None:
    path = write_dataset(tmp_path / "d.h5", [make_demo(1)])
    with pytest.raises(DatasetError, match="exists"):
        write_dataset(path, [make_demo(2)])
    assert read_dataset(path) == [make_demo(1)]
    write_dataset(path, [make_demo(2)], overwrite=True)
    assert read_dataset(path) == [make_demo(2)]


def test_invalid_demo_leaves_no_file(tmp_path: Path) -> None:
    path = tmp_path / "d.h5"
    with pytest.raises(DatasetError, match="not a Demonstration"):
        write_dataset(path, [make_demo(1), {"t": [0, 1]}])  # type: ignore[list-item]
    with pytest.raises(DatasetError, match="no demonstrations"):
        write_dataset(path, [])
    assert list(tmp_path.iterdir()) == []


def test_failure_midway_leaves_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "d.h5"
    write_dataset(path, [make_demo(1)])
    real = ds._write_demo
    calls = []

    def flaky(group: h5py.Group, demo: Demonstration) -> None:
        calls.append(1)
        if len(calls) == 2:
            raise OSError("disk full")
        real(group, demo)

    monkeypatch.setattr(ds, "_write_demo", flaky)
    with pytest.raises(OSError, match="disk full"):
        write_dataset(tmp_path / "new.h5", [make_demo(1), make_demo(2)])
    assert not (tmp_path / "new.h5").exists()
    calls.clear()
    with pytest.raises(OSError, match="disk full"):
        write_dataset(path, [make_demo(3), make_demo(4)], overwrite=True)
    calls.clear()
    with pytest.raises(OSError, match="disk full"):
        append_dataset(path, [make_demo(5), make_demo(6)])
    assert read_dataset(path) == [make_demo(1)]  # the old file is untouched
    assert tmp_leftovers(tmp_path) == []


def test_append(tmp_path: Path) -> None:
    path = tmp_path / "d.h5"
    append_dataset(path, [make_demo(1)])  # creates
    append_dataset(path, [make_demo(2), make_demo(3)])
    assert read_dataset(path) == [make_demo(1), make_demo(2), make_demo(3)]
    assert read_demo(f"{path}:2") == make_demo(3)
    assert tmp_leftovers(tmp_path) == []


def test_bad_files(tmp_path: Path) -> None:
    with pytest.raises(DatasetError, match="no such file") as info:
        read_dataset(tmp_path / "missing.h5")
    assert info.value.path == str(tmp_path / "missing.h5")
    text = tmp_path / "notes.h5"
    text.write_text("not hdf5\n")
    with pytest.raises(DatasetError, match="not an HDF5 file"):
        read_dataset(text)
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f.attrs["format"] = "something-else"
    with pytest.raises(DatasetError, match="something-else"):
        read_dataset(other)
    with pytest.raises(DatasetError, match="format"):
        read_demo(f"{other}:0")


def _edit(path: Path, edit) -> None:
    with h5py.File(path, "r+") as f:
        edit(f)


@pytest.mark.parametrize(
    ("edit", "match", "column", "row"),
    [
        (lambda f: f.attrs.__setitem__("format_version", 2), "format_version 2", None, None),
        (lambda f: f["demos/001"].__delitem__("pos"), "no dataset 'pos'", "pos", None),
        (lambda f: f["demos/001/pos"].__setitem__((4, 2), np.nan), "non-finite", "pos", 4),
        (lambda f: f["demos/001"].attrs.__setitem__("meta", "{bad"), "meta JSON", "meta", None),
        (lambda f: f["demos/001"].attrs.__delitem__("task"), "'task'", "task", None),
    ],
)
def test_corrupt_file(
    tmp_path: Path, edit, match: str, column: str | None, row: int | None
) -> None:
    path = write_dataset(tmp_path / "d.h5", [make_demo(1), make_demo(2)])
    _edit(path, edit)
    with pytest.raises(DatasetError, match=match) as info:
        read_dataset(path)
    assert info.value.path == str(path)
    assert (info.value.column, info.value.row) == (column, row)
    assert str(path) in str(info.value)


def test_strings_complex_numbers_empty_and_damaged_files_are_refused(tmp_path: Path) -> None:
    path = write_dataset(tmp_path / "d.h5", [make_demo(1)])
    for label, bad in (("t", lambda a: a.astype("S")), ("pos", lambda a: a + 1j)):
        copy = tmp_path / f"{label}.h5"
        copy.write_bytes(path.read_bytes())
        with h5py.File(copy, "r+") as f:
            data = f[f"demos/000/{label}"][()]
            del f[f"demos/000/{label}"]
            f[f"demos/000/{label}"] = bad(data)
        with pytest.raises(DatasetError, match=f"column '{label}'.*not real numbers"):
            read_dataset(copy)
    empty = tmp_path / "empty.h5"
    empty.write_bytes(path.read_bytes())
    with h5py.File(empty, "r+") as f:
        del f["demos/000"]
    with pytest.raises(DatasetError, match="holds no demonstrations"):
        read_dataset(empty)
    # a damaged metadata block (found by flipping bytes: h5py raises OSError/RuntimeError)
    raw = bytearray(path.read_bytes())
    refused = 0
    for off in range(96, 6000, 97):
        bad = bytearray(raw)
        bad[off : off + 64] = bytes(b ^ 0xA5 for b in bad[off : off + 64])
        (tmp_path / "x.h5").write_bytes(bytes(bad))
        try:
            read_dataset(tmp_path / "x.h5")
        except DatasetError:
            refused += 1
    assert refused > 5  # and nothing else escaped


def test_umask_and_an_old_files_mode_are_kept(tmp_path: Path) -> None:
    old = os.umask(0o077)
    try:
        private = write_dataset(tmp_path / "private.h5", [make_demo(1)])
        shared = write_dataset(tmp_path / "shared.h5", [make_demo(1)])
        shared.chmod(0o640)
        append_dataset(shared, [make_demo(2)])
    finally:
        os.umask(old)
    assert private.stat().st_mode & 0o777 == 0o600
    assert shared.stat().st_mode & 0o777 == 0o640 and len(read_dataset(shared)) == 2


def _linked_demos(f: h5py.File, target: Path) -> None:
    del f["demos"]
    f["demos"] = h5py.ExternalLink(str(target), "/demos")


@pytest.mark.parametrize(
    ("edit", "match", "column"),
    [
        (lambda f: f["demos"].__delitem__("001") or f["demos"].__setitem__("001", np.zeros(5)),
         "/demos/001 is a dataset, not a group", None),
        (lambda f: f["demos/001"].attrs.__setitem__("task", 7),
         "/demos/001: attribute 'task' is 7 \\(int64\\), not a text string", "task"),
        (lambda f: f["demos/001"].attrs.__setitem__("source", [b"synthetic"]),
         "attribute 'source' is \\['synthetic'\\] \\(ndarray\\)", "source"),
        (lambda f: f["demos/001"].__delitem__("t") or f["demos/001"].create_dataset(
            "t", shape=(400_000_000,), dtype="f8", chunks=(1 << 20,), compression="gzip"),
         r"/demos/001/t declares \(400000000,\) values \(3.0 GiB\) in a file of", "t"),
        (lambda f: f["demos/001"].__delitem__("pos") or f["demos/001"].create_group("pos"),
         "/demos/001/pos is a group, not a dataset", "pos"),
    ],
)  # fmt: skip
def test_crafted_structures_are_refused_before_reading(
    tmp_path: Path, edit, match: str, column: str | None
) -> None:
    path = write_dataset(tmp_path / "d.h5", [make_demo(1), make_demo(2)])
    _edit(path, edit)
    before = path.read_bytes()
    for read in (read_dataset, lambda p: read_demo(f"{p}:1"), dataset_summary):
        with pytest.raises(DatasetError, match=match) as info:
            read(path)
        assert info.value.path == str(path) and info.value.column == column
    with pytest.raises(DatasetError, match=match):
        append_dataset(path, [make_demo(3)])
    assert path.read_bytes() == before and tmp_leftovers(tmp_path) == []


def test_links_to_other_files_are_refused_and_never_written_through(tmp_path: Path) -> None:
    target = write_dataset(tmp_path / "target.h5", [make_demo(1)])
    linked = write_dataset(tmp_path / "linked.h5", [make_demo(2)])
    _edit(linked, lambda f: _linked_demos(f, target))
    data = tmp_path / "data.bin"
    data.write_bytes(np.arange(25, dtype=np.float64).tobytes())
    stored = write_dataset(tmp_path / "stored.h5", [make_demo(3)])
    _edit(stored, lambda f: f["demos/000"].__delitem__("t") or f["demos/000"].create_dataset(
        "t", shape=(25,), dtype="f8", external=[(str(data), 0, 200)]))  # fmt: skip
    before = {p: p.read_bytes() for p in (target, linked, stored)}
    message = f"/demos is an external link to {target}:/demos; teachfit follows no links"
    for read in (read_dataset, read_demo, lambda p: append_dataset(p, [make_demo(4)])):
        with pytest.raises(DatasetError, match=message):
            read(linked)
        with pytest.raises(DatasetError, match="/demos/000/t keeps its data in other files"):
            read(stored)
    with pytest.raises(DatasetError, match="external link"):
        ds.check_appendable(linked)
    assert {p: p.read_bytes() for p in before} == before and tmp_leftovers(tmp_path) == []
