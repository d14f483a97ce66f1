"""The watchdog of a local Ray instance, without Ray: what a driver starts after it is killed
with the driver (``kill -9``) or when the driver stops it; what the driver started before, and
the driver's other processes, are left alone."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import teachfit

SRC = str(Path(teachfit.__file__).resolve().parents[1])

#: a driver: a child before the watchdog, two after it (one a grandchild, as the raylet's
#: agents are), all noted; prints their PIDs, then (told so on stdin) stops the watchdog, or
#: waits to be killed
DRIVER = """
import subprocess, sys, time
from teachfit.learning.ray_reaper import Reaper
before = subprocess.Popen(["sleep", "300"])
reaper = Reaper()
child = subprocess.Popen(["sleep", "300"])
shell = subprocess.Popen(
    ["sh", "-c", "sleep 300 & echo $!; wait"], stdout=subprocess.PIPE, text=True
)
grandchild = int(shell.stdout.readline())
reaper.note()
print(before.pid, child.pid, shell.pid, grandchild, flush=True)
if sys.argv[1] == "stop":
    sys.stdin.readline()  # the test has seen them all alive: stop now
    reaper.stop()
    print("stopped", flush=True)
time.sleep(300)
"""


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rpartition(")")[2].split()[0] not in ("Z", "X")
    except OSError:
        return False


def _gone(pids: list[int]) -> bool:
    deadline = time.monotonic() + 10  # bounds the wait; the kill takes milliseconds
    while any(_alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.05)
    return not any(_alive(p) for p in pids)


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="the watchdog reads /proc")
@pytest.mark.parametrize("end", ["kill", "stop"])
def test_what_the_driver_started_after_the_watchdog_ends_with_it(end: str) -> None:
    proc = subprocess.Popen(
        [sys.executable, "-c", DRIVER, end],
        env=dict(os.environ, PYTHONPATH=SRC),
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    started: list[int] = []
    try:
        assert proc.stdout is not None
        before, *after = (int(x) for x in proc.stdout.readline().split())
        started = [before, *after]
        assert all(_alive(p) for p in started)
        if end == "kill":
            proc.send_signal(signal.SIGKILL)
        else:
            assert proc.stdin is not None
            proc.stdin.write("go\n")  # not before the check above: the stop would race it
            proc.stdin.flush()
            assert proc.stdout.readline().strip() == "stopped"
        assert _gone(after)
        assert _alive(before)  # started before the watchdog: not the instance's
        assert end == "kill" or proc.poll() is None  # the driver itself lives on
    finally:
        proc.kill()
        proc.wait()
        for pid in started:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
