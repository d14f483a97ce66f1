"""Atomic output: old file kept and no temporary left on failure; no direct writes in src."""

from __future__ import annotations

import ast
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from teachfit.core import atomic
from teachfit.core.atomic import atomic_append_text, atomic_path, atomic_write_text
from teachfit.core.errors import OutputError, TeachfitError

SRC = Path(atomic.__file__).resolve().parents[1]


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if atomic.TMP_MARK in p.name)


def test_write_creates_the_folder_and_replaces(tmp_path: Path) -> None:
    dest = tmp_path / "new" / "deeper" / "m.json"
    atomic_write_text(dest, "one")
    atomic_write_text(dest, "two")
    assert dest.read_text() == "two"
    assert dest.stat().st_mode & 0o777 == 0o666 & ~atomic.current_umask()
    atomic_append_text(dest, "+three")
    assert dest.read_text() == "two+three"
    assert leftovers(dest.parent) == []


def mode(path: Path) -> int:
    return path.stat().st_mode & 0o777


@pytest.mark.parametrize("umask", [0o077, 0o022, 0o002])
def test_new_files_follow_the_umask_and_old_files_keep_their_mode(
    tmp_path: Path, umask: int
) -> None:
    old = os.umask(umask)
    try:
        assert atomic.current_umask() == umask
        new = atomic_write_text(tmp_path / "new.txt", "x")
        private = atomic_write_text(tmp_path / "private.txt", "a")
        private.chmod(0o600)
        atomic_append_text(private, "b")  # an append keeps the file's own mode
        shared = atomic_write_text(tmp_path / "shared.txt", "a")
        shared.chmod(0o664)
        atomic_write_text(shared, "c")  # so does a replace
    finally:
        os.umask(old)
    assert mode(new) == 0o666 & ~umask
    assert (mode(private), private.read_text()) == (0o600, "ab")
    assert (mode(shared), shared.read_text()) == (0o664, "c")
    assert leftovers(tmp_path) == []


def test_temporary_keeps_the_suffix(tmp_path: Path) -> None:
    with atomic_path(tmp_path / "fig.png") as tmp:
        assert tmp.parent == tmp_path and tmp.suffix == ".png" and tmp.name.startswith(".")
        tmp.write_bytes(b"png")
    assert (tmp_path / "fig.png").read_bytes() == b"png"


@pytest.mark.parametrize("exc", [KeyboardInterrupt, RuntimeError, OSError])
def test_failure_midway_keeps_the_old_file(tmp_path: Path, exc: type[BaseException]) -> None:
    dest = atomic_write_text(tmp_path / "p.toml", "old")
    with pytest.raises(exc), atomic_path(dest) as tmp:
        tmp.write_text("half of the new")
        raise exc("stopped")
    assert dest.read_text() == "old"
    assert leftovers(tmp_path) == []


def test_write_errors_are_one_clear_teachfit_error(tmp_path: Path) -> None:
    blocker = tmp_path / "afile"
    blocker.write_text("x")
    with pytest.raises(OutputError, match=r"folder of figure .*afile/f.png: .*afile is a file"):
        atomic_write_text(blocker / "f.png", "x", "figure")
    with pytest.raises(OutputError, match="it is a folder"):
        atomic_write_text(tmp_path, "x")
    with pytest.raises(OutputError, match="nothing was written"), atomic_path(tmp_path / "v.mp4"):
        pass
    assert issubclass(OutputError, TeachfitError) and issubclass(OutputError, OSError)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


def test_killed_process_leaves_the_old_file_and_no_temporary(tmp_path: Path) -> None:
    """A real process killed by SIGTERM (``kill``, ``timeout``; with the CLI's handler) while
    it writes (Ctrl-C's KeyboardInterrupt is the in-process test above)."""
    sig = signal.SIGTERM
    dest = atomic_write_text(tmp_path / "model.json", "old")
    code = (
        "import sys, time\n"
        "from teachfit.cli.common import exit_on_sigterm\n"
        "from teachfit.core.atomic import atomic_path\n"
        "exit_on_sigterm()\n"
        "with atomic_path(sys.argv[1]) as tmp, open(tmp, 'xb') as fh:\n"
        "    fh.write(b'half'); fh.flush(); print('writing', flush=True); time.sleep(30)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(SRC.parent)}
    proc = subprocess.Popen(
        [sys.executable, "-c", code, str(dest)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        env=env, text=True,
    )  # fmt: skip
    try:
        assert proc.stdout is not None and proc.stdout.readline() == "writing\n"
        assert len(leftovers(tmp_path)) == 1  # the temporary exists while it writes
        proc.send_signal(sig)
        proc.wait(timeout=20)
    finally:
        proc.kill()
        proc.wait()
    assert proc.returncode != 0
    assert dest.read_text() == "old"
    assert leftovers(tmp_path) == []


def test_what_a_kill_9_leaves_is_swept_by_the_next_write(tmp_path: Path) -> None:
    """SIGKILL cannot be caught: its temporary stays until a later write of the same file
    finds its writer gone (and the file old): then it is removed."""
    dest = atomic_write_text(tmp_path / "model.json", "old")
    code = (
        "import sys, time\n"
        "from teachfit.core.atomic import atomic_path\n"
        "with atomic_path(sys.argv[1]) as tmp, open(tmp, 'xb') as fh:\n"
        "    fh.write(b'half'); fh.flush(); print('writing', flush=True); time.sleep(30)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(SRC.parent)}
    proc = subprocess.Popen(
        [sys.executable, "-c", code, str(dest)], stdout=subprocess.PIPE, env=env, text=True
    )
    try:
        assert proc.stdout is not None and proc.stdout.readline() == "writing\n"
    finally:
        proc.kill()
        proc.wait()
    (left,) = leftovers(tmp_path)
    assert dest.read_text() == "old"
    atomic_write_text(dest, "new")  # young: a writer elsewhere may still own it
    assert leftovers(tmp_path) == [left]
    old = os.stat(tmp_path / left).st_mtime - 2 * atomic.STALE_AFTER
    os.utime(tmp_path / left, (old, old))
    live = atomic.temporary_name(dest)  # this process's own temporary: its writer is alive
    live.write_bytes(b"x")
    os.utime(live, (old, old))
    atomic_write_text(dest, "newer")
    assert leftovers(tmp_path) == [live.name] and dest.read_text() == "newer"


#: calls that write a file; allowed only on a path from atomic_path (named ``tmp``) or in
#: core/atomic.py itself
WRITERS = {"savefig", "write_text", "write_bytes", "get_writer", "imwrite", "save", "savez",
           "tofile", "copyfile", "replace", "rename", "mkstemp", "File"}  # fmt: skip


def _direct_writes(tree: ast.AST) -> list[tuple[int, str]]:
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
        first = node.args[0] if node.args else None
        if name == "copyfile":  # copyfile(src, dst)
            first = node.args[1] if len(node.args) > 1 else None
        # a temporary from atomic_path, or a file handle opened on one
        on_tmp = isinstance(first, ast.Name) and first.id in {"tmp", "fh", "buf"}
        if name in {"replace", "rename", "mkstemp"}:
            on_tmp = False  # moving files into place is the helper's job alone
        target = isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
        if name == "open":
            modes = [a for a in node.args[1:2] if isinstance(a, ast.Constant)]
            modes += [k.value for k in node.keywords if k.arg == "mode"]
            if isinstance(func, ast.Attribute):  # Path.open(mode)
                modes = [a for a in node.args[:1] if isinstance(a, ast.Constant)]
                on_tmp = target and func.value.id == "tmp"  # type: ignore[union-attr]
            writes = any(
                isinstance(m, ast.Constant) and set(str(m.value)) & set("wax+") for m in modes
            )
            if writes and not on_tmp:
                found.append((node.lineno, "open for writing"))
        elif name == "File":  # h5py.File(path, mode)
            modes = [a for a in node.args[1:2] if isinstance(a, ast.Constant)]
            modes += [k.value for k in node.keywords if k.arg == "mode"]
            writes = any(isinstance(m, ast.Constant) and m.value != "r" for m in modes)
            if writes and not on_tmp:
                found.append((node.lineno, "h5py.File for writing"))
        elif name in {"write_text", "write_bytes"}:
            if not (target and func.value.id == "tmp"):  # type: ignore[union-attr]
                found.append((node.lineno, name))
        elif name in WRITERS - {"File"} and not on_tmp:
            if name in {"replace", "rename"} and not (target and func.value.id == "os"):  # type: ignore[union-attr]
                continue  # str.replace, dataclasses.replace, Path.rename is caught below
            if name == "save" and not (target and func.value.id in {"np", "numpy"}):  # type: ignore[union-attr]
                continue  # model.save(path) goes through the helper itself
            found.append((node.lineno, name))
    return found


def test_no_direct_writes_remain_in_src() -> None:
    offenders = []
    for path in sorted(SRC.rglob("*.py")):
        if path.name == "atomic.py" and path.parent.name == "core":
            continue
        for line, what in _direct_writes(ast.parse(path.read_text(), str(path))):
            offenders.append(f"{path.relative_to(SRC)}:{line}: {what}")
    assert offenders == [], "write through teachfit.core.atomic:\n" + "\n".join(offenders)


def test_the_scan_finds_direct_writes() -> None:
    bad = (
        "fig.savefig(path)\np.write_text('x')\nopen(p, 'w')\np.open('a')\nnp.save(p, a)\n"
        "h5py.File(p, 'w')\nos.replace(a, b)\nimageio.get_writer(out)\nshutil.copyfile(tmp, p)\n"
        "os.replace(tmp, p)\ntempfile.mkstemp(dir=d)\n"
    )
    assert len(_direct_writes(ast.parse(bad))) == 11
    good = (
        "fig.savefig(tmp)\ntmp.write_text('x')\nopen(tmp, 'xb')\nopen(p)\nnp.save(fh, a)\n"
        "h5py.File(p, 'r')\nh5py.File(tmp, 'x')\ns.replace('a', 'b')\nshutil.copyfile(p, tmp)\n"
    )
    assert _direct_writes(ast.parse(good)) == []
