"""Worker processes die with their parent, even a ``kill -9`` ed one, and keep no inherited
signal handlers; a second Ctrl-C aborts with a clear line and exit status 130."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

import teachfit
from teachfit.learning.claims import pid_alive
from teachfit.learning.runner import Interrupts

SRC = str(Path(teachfit.__file__).resolve().parents[1])
CLI = [sys.executable, "-c", "from teachfit.cli import main; main()", "learn", "skill"]
QUICK = ["--task", "puzzle", "--method", "cmaes", "--trials", "300"]


def _learn(db: Path, *args: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [*CLI, *QUICK, "--study", str(db), *args],
        env=dict(os.environ, PYTHONPATH=SRC, COLUMNS="200"),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )


def _keys(db: Path) -> list[str]:
    """Keys of the finished trials (read with sqlite3 itself, not through teachfit)."""
    try:
        with sqlite3.connect(db, timeout=30) as con:
            q = (
                "SELECT a.value_json FROM trial_user_attributes a JOIN trials t "
                "ON a.trial_id = t.trial_id WHERE a.key = 'key' AND t.state = 'COMPLETE'"
            )
            return [str(r[0]) for r in con.execute(q)]
    except sqlite3.OperationalError:  # tables not created yet
        return []


def _wait_stored(proc: subprocess.Popen[str], db: Path, n: int, timeout: float = 180) -> int:
    deadline = time.monotonic() + timeout
    while (k := len(_keys(db))) < n:
        assert proc.poll() is None, proc.communicate()[0]
        assert time.monotonic() < deadline, f"only {k} trial(s) after {timeout} s"
        time.sleep(0.05)
    return k


def _wait_running(proc: subprocess.Popen[str], db: Path, timeout: float = 180) -> None:
    """Until a claimed key is running that no finished trial holds: a trial has begun."""
    q = "SELECT key FROM teachfit_claims WHERE state = 'running'"
    deadline = time.monotonic() + timeout
    while True:
        try:
            with sqlite3.connect(db, timeout=30) as con:
                running = {str(r[0]) for r in con.execute(q)}
        except sqlite3.OperationalError:
            running = set()
        if running - {json.loads(k) for k in _keys(db)}:
            return
        assert proc.poll() is None, proc.communicate()[0]
        assert time.monotonic() < deadline, f"no trial running after {timeout} s"
        time.sleep(0.02)


def _children(pid: int) -> dict[int, int]:
    """PID -> start time of the processes whose parent is ``pid``."""
    out = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    fields = fh.read().rpartition(")")[2].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                out[int(entry)] = int(fields[19])
    return out


def _caught(pid: int) -> int:
    """Mask of the signals process ``pid`` has handlers for (``SigCgt``)."""
    with open(f"/proc/{pid}/status") as fh:
        line = next(ln for ln in fh if ln.startswith("SigCgt:"))
    return int(line.split()[1], 16)


def _bit(sig: signal.Signals) -> int:
    return 1 << (int(sig) - 1)


def test_workers_die_with_a_killed_parent_and_finished_trials_stay(tmp_path: Path) -> None:
    db = tmp_path / "orphans.db"
    proc = _learn(db, "--starts", "1", "--workers", "2")
    try:
        _wait_stored(proc, db, 3)
        workers = _children(proc.pid)
        assert len(workers) >= 2, workers  # the pool's worker processes
        parent_caught = _caught(proc.pid)
        assert parent_caught & _bit(signal.SIGTERM)  # the parent stops gracefully on SIGTERM
        for pid in workers:  # workers have the default actions, not the parent's handlers
            assert not _caught(pid) & (_bit(signal.SIGTERM) | _bit(signal.SIGINT)), pid
            assert os.getpgid(pid) == pid  # own group: a terminal's Ctrl-C is the parent's
        before = set(_keys(db))
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        deadline = time.monotonic() + 10
        while (left := [p for p, t in workers.items() if pid_alive(p, t)]) and (
            time.monotonic() < deadline
        ):
            time.sleep(0.05)
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.communicate()
    print(f"\nkill -9 of the parent with {len(workers)} workers: orphans left {len(left)}")
    assert left == []
    after = _keys(db)
    assert before <= set(after) and len(after) == len(set(after)) >= 3


def test_a_second_ctrl_c_aborts_with_a_clear_line_and_status_130(tmp_path: Path) -> None:
    db = tmp_path / "twice.db"
    # trials of 16 executions, ~3 s on an idle machine (4 took ~0.7 s: the running trial
    # could finish, and the run end normally, before the second Ctrl-C arrived)
    proc = _learn(db, "--starts", "16", "--workers", "1")
    try:
        n = _wait_stored(proc, db, 1)
        # a trial is running (the first Ctrl-C between a store and the next ask ended the run
        # at once, and the second arrived after the command had ended: the CI failure)
        _wait_running(proc, db)
        workers = _children(proc.pid)
        proc.send_signal(signal.SIGINT)
        time.sleep(0.4)  # the first is handled (stop asking) before the second arrives
        assert proc.poll() is None
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 130, out
    assert "interrupted again" in out and "--resume" in out and "Traceback" not in out
    keys = _keys(db)
    assert len(keys) == len(set(keys)) >= n  # the finished trials are stored
    assert f"the {len(keys)} finished trial(s) are stored" in out
    assert not [p for p, t in workers.items() if pid_alive(p, t)]  # the pool was ended


def test_a_nested_guard_is_the_outer_one_and_a_third_signal_is_ignored() -> None:
    before = signal.getsignal(signal.SIGINT)
    with Interrupts() as outer:
        with Interrupts() as inner:
            assert inner is outer
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)  # the handler runs between bytecodes of the main thread
        assert outer.stop and not outer.aborted
        assert signal.getsignal(signal.SIGINT) == outer._handle  # the inner exit kept it
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.5)
        assert outer.aborted
        os.kill(os.getpid(), signal.SIGINT)  # aborting already: ignored, no second raise
        time.sleep(0.01)
    assert signal.getsignal(signal.SIGINT) == before
