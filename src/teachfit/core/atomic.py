"""Atomic file output: every file teachfit produces goes through :func:`atomic_path`.

A file is written to a hidden temporary file in the destination's folder, flushed to disk
(``fsync``) and moved onto the destination with ``os.replace``, so a reader (or a user after a
crash, a full disk, ``kill -9`` or Ctrl-C) sees the old file or the new one, never half of one.
On any exception, ``KeyboardInterrupt`` included, the temporary file is removed and the old file
is left as it was.

Policy for a missing output folder: it is created (with its parents), as ``mkdir -p`` would; a
folder that cannot be created (a file in the way, no permission) is an :class:`OutputError`
naming the file. Write errors (full disk, read-only file system) are :class:`OutputError` too;
a full disk, a full quota and the file-size limit (``ulimit -f``) are said so in words.

Permissions: a new file gets ``0o666 & ~umask`` (what ``open`` gives, so ``umask 077`` keeps
outputs private); a replaced or appended file keeps its own permission bits.

The standard library has the pieces (``os.replace``, ``os.fsync``) but no atomic-write helper;
the one maintained package for it (``atomicwrites``) is archived, hence this module.
"""

from __future__ import annotations

import errno
import os
import stat
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from teachfit.core.errors import OutputError

#: marker in every temporary file's name (``.NAME.<pid>-<hex>.tmp.SUFFIX``)
TMP_MARK = ".tmp"
#: a left-over temporary is swept only when its writer is gone and it is this old (s): a
#: writer on another machine sharing the folder has no PID here, so age alone guards it
STALE_AFTER = 600.0
#: write errors that mean a limit was hit: what happened and the fix, in words
LIMITS = {
    errno.ENOSPC: ("the disk is full", "free space or write elsewhere"),
    errno.EDQUOT: ("the disk quota is exceeded", "free space or write elsewhere"),
    errno.EFBIG: ("the file-size limit was hit", "raise it (ulimit -f) or write less"),
}


def temporary_name(dest: Path) -> Path:
    """A hidden temporary path next to ``dest`` that keeps its suffix (``.png``, ``.mp4``...),
    so that writers which pick the format from the file name (matplotlib, ffmpeg, numpy) still
    do. It carries the writer's PID, so a later write can sweep what a killed one left."""
    token = f"{os.getpid()}-{uuid.uuid4().hex[:12]}"
    return dest.with_name(f".{dest.name}.{token}{TMP_MARK}{dest.suffix}")


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def sweep_stale(dest: Path, now: float | None = None) -> list[Path]:
    """Remove the temporaries of ``dest`` that a killed writer (``kill -9``, power loss) left:
    its PID is gone and the file is older than :data:`STALE_AFTER`. Returns what was removed."""
    import time

    now = time.time() if now is None else now
    removed = []
    for tmp in dest.parent.glob(f".{glob_escape(dest.name)}.*{TMP_MARK}{dest.suffix}"):
        token = tmp.name[len(dest.name) + 2 :].split(TMP_MARK)[0]
        pid_text = token.split("-", 1)[0]
        try:
            stale = now - tmp.stat().st_mtime > STALE_AFTER
        except OSError:
            continue
        if stale and pid_text.isdigit() and not _pid_alive(int(pid_text)):
            tmp.unlink(missing_ok=True)
            removed.append(tmp)
    return removed


def glob_escape(name: str) -> str:
    """``name`` with glob's special characters taken literally."""
    return "".join(f"[{c}]" if c in "*?[" else c for c in name)


def ensure_parent(dest: str | Path, what: str = "file") -> Path:
    """Create ``dest``'s folder if it is missing; :class:`OutputError` if that is impossible."""
    dest = Path(dest)
    if dest.is_dir():
        raise OutputError(f"cannot write {what} {dest}: it is a folder; give a file name")
    ensure_folder(dest.parent, f"the folder of {what} {dest}")
    return dest


def ensure_folder(folder: str | Path, what: str = "the output folder") -> Path:
    """Create an output folder (and its parents); :class:`OutputError` if that is impossible."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        why = exc.strerror or str(exc)
        blocker = next((p for p in (folder, *folder.parents) if p.exists()), None)
        if blocker is not None and not blocker.is_dir():
            why = f"{blocker} is a file, not a folder"
        raise OutputError(f"cannot create {what}: {why}") from exc
    return folder


def _fsync(path: Path, directory: bool = False) -> None:
    fd = os.open(path, os.O_RDONLY | (os.O_DIRECTORY if directory else 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def current_umask() -> int:
    """This process's umask (read from ``/proc``; elsewhere set and restored at once)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def output_mode(dest: Path) -> int:
    """Permission bits for a file written to ``dest``: those of the regular file there (a
    replace or an append keeps them), else ``0o666 & ~umask`` (a new file, as ``open`` makes)."""
    try:
        st = os.lstat(dest)
    except OSError:
        st = None
    if st is not None and stat.S_ISREG(st.st_mode):
        return stat.S_IMODE(st.st_mode) & 0o777
    return 0o666 & ~current_umask()


def write_error(exc: OSError) -> str:
    """Why a write failed, in one line (a hit limit in words)."""
    if exc.errno in LIMITS:
        words, fix = LIMITS[exc.errno]
        return f"{words} ({os.strerror(exc.errno)}): {fix}"
    return " ".join((exc.strerror or str(exc)).split())


@contextmanager
def atomic_path(dest: str | Path, what: str = "file", mode: int | None = None) -> Iterator[Path]:
    """Yield a temporary path to write; on success it replaces ``dest`` atomically.

    ``what`` names the file in error messages ("model file", "figure"). ``mode`` is the
    permission bits of the result; by default :func:`output_mode` (an existing file's own, a
    new file's from the umask).

    Raises
    ------
    OutputError
        The folder cannot be created, the body wrote nothing, or writing failed with an
        ``OSError`` (the error's text is kept). Other exceptions propagate unchanged; in every
        case the temporary file is removed and ``dest`` is untouched.
    """
    dest = ensure_parent(dest, what)
    tmp = temporary_name(dest)
    try:
        yield tmp
        if not tmp.is_file():
            raise OutputError(f"cannot write {what} {dest}: nothing was written")
        os.chmod(tmp, output_mode(dest) if mode is None else mode)
        _fsync(tmp)
        os.replace(tmp, dest)
        _fsync(dest.parent, directory=True)
        sweep_stale(dest)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        if isinstance(exc, OutputError):
            raise
        raise OutputError(f"cannot write {what} {dest}: {write_error(exc)}") from exc
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def atomic_write_bytes(dest: str | Path, data: bytes, what: str = "file") -> Path:
    """Write ``data`` to ``dest`` atomically; returns ``dest`` as a :class:`Path`."""
    dest = Path(dest)
    with atomic_path(dest, what) as tmp, open(tmp, "xb") as fh:
        fh.write(data)
    return dest


def atomic_write_text(dest: str | Path, text: str, what: str = "file") -> Path:
    """Write ``text`` (UTF-8) to ``dest`` atomically; returns ``dest`` as a :class:`Path`."""
    return atomic_write_bytes(dest, text.encode("utf-8"), what)


def atomic_append_text(dest: str | Path, text: str, what: str = "file") -> Path:
    """Append ``text`` to ``dest`` (created if missing): the old content plus ``text`` is
    written as a new file and moved into place, so a failed append leaves the old file."""
    dest = Path(dest)
    old = b""
    if dest.is_file():
        try:
            old = dest.read_bytes()
        except OSError as exc:
            raise OutputError(f"cannot read {what} {dest}: {exc.strerror or exc}") from exc
    return atomic_write_bytes(dest, old + text.encode("utf-8"), what)
