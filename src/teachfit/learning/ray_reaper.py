"""Stop a local Ray instance's processes with the process that started it.

The kernel kills Ray's GCS server and raylet with the driver that started them, but not what
the raylet starts (its agents, workers): after ``kill -9`` of the driver they wait a minute or
more for the dead GCS server. :class:`Reaper` runs this file as a watchdog beside the driver,
started before ``ray.init``: it notes every process the driver starts from then on (the
driver's descendants, every :data:`SCAN_S` seconds and when asked, :meth:`Reaper.note`) and,
when the driver is done with Ray (:meth:`Reaper.stop`, after ``ray.shutdown()``) or dies (its
end of a pipe closes), SIGKILLs those of them still running. A process is killed only if its
start time is the one noted (a PID the system gave to another process since is left alone).

The watchdog uses the standard library only (it runs as ``python -I ray_reaper.py``), ignores
Ctrl-C and SIGTERM sent to the driver's process group (the driver then stops Ray itself and
lets the watchdog go), and lives no longer than the driver.
"""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys

#: seconds between two looks at the driver's descendants
SCAN_S = 0.25


def _stat(pid: int) -> tuple[int, int] | None:
    """``(parent PID, start time in clock ticks)`` of a live process, or ``None``."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            fields = fh.read().rpartition(")")[2].split()
    except (OSError, ValueError):
        return None
    if not fields or fields[0] in ("Z", "X"):
        return None
    return int(fields[1]), int(fields[19])


def _children(pid: int) -> list[int]:
    """The children of process ``pid`` (Linux's per-thread ``children`` lists)."""
    out: list[int] = []
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return out
    for tid in tasks:
        try:
            with open(f"/proc/{pid}/task/{tid}/children") as fh:
                out += [int(x) for x in fh.read().split()]
        except (OSError, ValueError):
            pass
    return out


def _all_children() -> dict[int, list[int]]:
    """Every process's children, from every process's parent (where ``children`` lists are
    not built into the kernel)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit() and (st := _stat(int(entry))) is not None:
            children.setdefault(st[0], []).append(int(entry))
    return children


def descendants(root: int) -> dict[int, int]:
    """The live descendants of process ``root``: PID -> start time (none without ``/proc``:
    there the watchdog watches nothing)."""
    me = os.getpid()
    if not os.path.isdir(f"/proc/{me}"):
        return {}
    if os.path.exists(f"/proc/{me}/task/{me}/children"):
        children = _children
    else:
        table = _all_children()
        children = lambda pid: table.get(pid, [])  # noqa: E731
    out: dict[int, int] = {}
    todo = children(root)
    while todo:
        pid = todo.pop()
        st = _stat(pid)
        if st is not None and pid not in out:
            out[pid] = st[1]
            todo.extend(children(pid))
    return out


def kill(seen: dict[int, int]) -> None:
    """SIGKILL the processes of ``seen`` (PID -> start time) that still run."""
    for pid, start in seen.items():
        st = _stat(pid)
        if st is not None and st[1] == start:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass


def main() -> None:
    """The watchdog: note the driver's new descendants until its pipe closes, then kill them."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    driver = os.getppid()
    before = set(descendants(driver))
    sys.stdout.write("ready\n")
    sys.stdout.flush()
    seen: dict[int, int] = {}
    while True:
        readable, _, _ = select.select([sys.stdin], [], [], SCAN_S)
        seen.update((p, s) for p, s in descendants(driver).items() if p not in before)
        if readable:
            if not sys.stdin.readline():
                break  # the driver closed its end: it is done with Ray, or dead
            sys.stdout.write("noted\n")  # asked by Reaper.note: all it started is noted
            sys.stdout.flush()
    kill(seen)


class Reaper:
    """The watchdog of a local Ray instance, started before ``ray.init`` (see the module)."""

    def __init__(self) -> None:
        self._proc = subprocess.Popen(
            [sys.executable, "-I", os.path.abspath(__file__)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        if not self._ask("ready"):
            self.stop()
            raise OSError("the watchdog of the local Ray instance did not start")

    def _ask(self, answer: str, question: str = "") -> bool:
        assert self._proc.stdin is not None and self._proc.stdout is not None
        try:
            if question:
                self._proc.stdin.write(question + "\n")
                self._proc.stdin.flush()
            return self._proc.stdout.readline().strip() == answer
        except OSError:
            return False

    def note(self) -> None:
        """Return once the watchdog has noted every process started so far (after
        ``ray.init``: the instance's servers and agents)."""
        if not self._ask("noted", "note"):
            raise OSError("the watchdog of the local Ray instance is gone")

    def stop(self) -> None:
        """Let the watchdog kill what is left of the instance (after ``ray.shutdown()``)
        and wait for it."""
        if self._proc.stdin is not None and not self._proc.stdin.closed:
            try:
                self._proc.stdin.close()
            except OSError:
                pass
        try:
            self._proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
        if self._proc.stdout is not None:
            self._proc.stdout.close()


if __name__ == "__main__":
    main()
