"""HDF5 written in memory then atomically (a full disk or ``ulimit -f`` is one clear error), and
read with links to other files, wrong kinds, wrong attribute types and huge declared sizes
refused before anything is read."""

from __future__ import annotations

import errno
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from teachfit.core import atomic, h5file
from teachfit.core.errors import DatasetError, OutputError
from teachfit.core.h5file import open_hdf5, write_hdf5

SRC = Path(h5file.__file__).resolve().parents[2]


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if atomic.TMP_MARK in p.name)


def fill_zeros(n: int):
    def fill(f: h5py.File) -> None:
        f.attrs["format"] = "x"
        f.create_dataset("a", data=np.arange(n, dtype=np.float64))

    return fill


def test_written_in_memory_then_atomically_and_appended(tmp_path: Path) -> None:
    path = write_hdf5(tmp_path / "f.h5", fill_zeros(10), "test file")
    write_hdf5(path, lambda f: f.create_dataset("b", data=[1, 2]), "test file", base=path)
    with open_hdf5(path) as reader:
        assert list(reader.dataset(reader.file, "a")) == list(range(10))
        assert list(reader.dataset(reader.file, "b")) == [1, 2]
        assert reader.text(reader.file, "format") == "x"
    assert leftovers(tmp_path) == []


def test_file_size_limit_is_one_error_and_keeps_the_old_file(tmp_path: Path) -> None:
    """``ulimit -f`` in a child process (SIGXFSZ ignored, as Python does): writing past the
    limit is an OutputError saying so; the old file stays and no temporary is left."""
    dest = write_hdf5(tmp_path / "f.h5", fill_zeros(10), "test file")
    old = dest.read_bytes()
    code = (
        "import sys, numpy as np\n"
        "from teachfit.core.errors import OutputError\n"
        "from teachfit.core.h5file import write_hdf5\n"
        "try:\n"
        "    write_hdf5(sys.argv[1], lambda f: f.create_dataset('a', data=np.ones(100_000)),"
        " 'test file')\n"
        "except OutputError as exc:\n"
        "    print(exc); sys.exit(2)\n"
    )

    def limit() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (64 * 1024, resource.RLIM_INFINITY))

    env = {**os.environ, "PYTHONPATH": str(SRC)}
    res = subprocess.run(
        [sys.executable, "-c", code, str(dest)], capture_output=True, text=True, env=env,
        preexec_fn=limit, timeout=120,
    )  # fmt: skip
    assert res.returncode == 2, res.stderr
    assert res.stderr == ""
    assert res.stdout.strip() == (
        f"cannot write test file {dest}: the file-size limit was hit (File too large): raise "
        "it (ulimit -f) or write less"
    )
    assert dest.read_bytes() == old and leftovers(tmp_path) == []


@pytest.mark.parametrize(
    ("code", "words"),
    [
        (errno.ENOSPC, "the disk is full \\(No space left on device\\): free space or"),
        (errno.EDQUOT, "the disk quota is exceeded \\(Disk quota exceeded\\): free space"),
        (errno.EIO, "Input/output error"),
    ],
)
def test_a_full_disk_is_said_in_words(tmp_path: Path, code: int, words: str) -> None:
    dest = tmp_path / "f.h5"
    with pytest.raises(OutputError, match=f"^cannot write test file {dest}: {words}"):
        with atomic.atomic_path(dest, "test file") as tmp:
            tmp.write_bytes(b"half")
            raise OSError(code, os.strerror(code))
    assert list(tmp_path.iterdir()) == []


def test_too_large_a_base_is_refused_before_reading(tmp_path: Path, monkeypatch) -> None:
    path = write_hdf5(tmp_path / "f.h5", fill_zeros(10), "test file")
    monkeypatch.setattr(h5file, "MAX_READ_BYTES", 100)
    with pytest.raises(DatasetError, match="over the 100 bytes teachfit appends to"):
        write_hdf5(path, fill_zeros(1), "test file", base=path)


def crafted(tmp_path: Path, edit) -> Path:
    path = write_hdf5(tmp_path / "c.h5", fill_zeros(10), "test file")
    with h5py.File(path, "r+") as f:
        edit(f)
    return path


def read_all(path: Path, kinds: str = "iuf") -> None:
    with open_hdf5(path) as reader:
        reader.dataset(reader.file, "a", kinds)
        reader.text(reader.file, "format")


def _external_storage(f: h5py.File) -> None:
    del f["a"]
    f.create_dataset("a", shape=(8,), dtype="f8", external=[("/etc/hostname", 0, 64)])


def _huge(f: h5py.File) -> None:
    del f["a"]
    f.create_dataset("a", shape=(400_000_000,), dtype="f8", chunks=(1 << 20,), compression=4)


def _a(value):
    """An edit that replaces dataset ``/a`` with ``value`` (a group for None)."""

    def edit(f: h5py.File) -> None:
        del f["a"]
        if value is None:
            f.create_group("a")
        else:
            f["a"] = value

    return edit


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda f: f.__setitem__("g", h5py.ExternalLink("/etc/hostname.h5", "/t")),
            "/g is an external link to /etc/hostname.h5:/t; teachfit follows no links",
        ),
        (
            lambda f: f.create_group("deep/er").__setitem__("x", h5py.ExternalLink("o.h5", "/")),
            "/deep/er/x is an external link to o.h5:/",
        ),
        (_external_storage, "/a keeps its data in other files"),
        (_huge, r"/a declares \(400000000,\) values \(3.0 GiB\) in a file of .* KiB: over the"),
        (_a(None), "/a is a group, not a dataset"),
        (_a("text"), "/a holds object values, not real numbers"),
        (_a(np.zeros(3, "c16")), "/a holds complex128 values"),
        (_a(np.zeros(3, [("x", "f8")])), r"/a holds \[\('x', '<f8'\)\] values"),
        (_a(h5py.Empty("f8")), "/a holds no values"),
        (lambda f: f.attrs.__setitem__("format", 7), "attribute 'format' is 7 \\(int64\\)"),
        (lambda f: f.attrs.__setitem__("format", [1.0, 2.0]), r"is \[1.0, 2.0\] \(ndarray\)"),
        (lambda f: f.attrs.__delitem__("format"), "/ has no attribute 'format'"),
        (lambda f: f.attrs.__setitem__("format", np.bytes_(b"\xff")), "is b'\\\\xff'"),
        (lambda f: f.__setitem__("s", h5py.SoftLink("/s")), None),  # not read: fine
    ],
)
def test_crafted_files_are_refused_before_reading(tmp_path: Path, edit, message) -> None:
    path = crafted(tmp_path, edit)
    if message is None:
        read_all(path)
        return
    with pytest.raises(DatasetError, match=message) as info:
        read_all(path)
    assert str(info.value).startswith(f"file {path}") and "\n" not in str(info.value)


def test_the_limit_counts_every_read(tmp_path: Path) -> None:
    """Each read counts, so soft links to one dataset cannot multiply what is read."""
    path = crafted(tmp_path, lambda f: [f.__setitem__(f"s{i}", h5py.SoftLink("/a")) for i in "12"])
    with open_hdf5(path, limit=200) as reader:
        reader.dataset(reader.file, "a")  # 80 bytes
        reader.dataset(reader.file, "s1")  # 160
        with pytest.raises(DatasetError, match="/s2 declares"):
            reader.dataset(reader.file, "s2")


def test_a_soft_link_loop_is_a_damaged_file(tmp_path: Path) -> None:
    path = crafted(tmp_path, _a(h5py.SoftLink("/a")))
    with pytest.raises(DatasetError, match="damaged HDF5 file.*too many links"):
        read_all(path)


def test_a_failing_fill_is_one_error_and_writes_nothing(tmp_path: Path) -> None:
    dest = write_hdf5(tmp_path / "f.h5", fill_zeros(3), "test file")
    old = dest.read_bytes()

    def broken(f: h5py.File) -> None:
        f.create_dataset("b", data=[1.0])
        raise OSError(errno.EIO, "Input/output error")

    with pytest.raises(OutputError, match=f"^cannot write test file {dest}: Input/output error$"):
        write_hdf5(dest, broken, "test file", base=dest)
    with pytest.raises(KeyboardInterrupt):
        write_hdf5(dest, lambda f: (_ for _ in ()).throw(KeyboardInterrupt), "test file")
    assert dest.read_bytes() == old and leftovers(tmp_path) == []
