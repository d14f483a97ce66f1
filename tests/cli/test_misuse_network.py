"""The misuse walk for network faults: a robot address where something listens but stays silent,
sends junk or refuses, Ctrl-C and SIGTERM while connecting, a simulator that dies mid-run, the
simulator's port taken. Each ends in one line naming the robot's address (or port) and the fix,
the documented exit status, no traceback, a run log holding every finished execution, and no
process left behind.

Listeners are the test's own processes on 127.0.0.1:1337 (libfranka's port cannot be changed),
stopped by their PID; the session's simulator is stopped meanwhile (``robot_port``).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path

import pytest
from typer.testing import CliRunner

pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")

from teachfit.cli import app  # noqa: E402
from teachfit.execution.recording import read_run_log  # noqa: E402
from teachfit.robot.franka.sim import SimServer  # noqa: E402

runner = CliRunner()
SRC = Path(__file__).parents[2] / "src"
#: the subprocesses run this checkout's teachfit
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])}
CHECK = ["robot", "check", "--host", "127.0.0.1", "--no-realtime", "--seconds", "0.1"]


def _children(pid: int, needle: bytes = b"pylibfranka") -> list[int]:
    """PIDs of ``pid``'s children whose command line holds ``needle`` (a connect probe)."""
    out = []
    for entry in Path("/proc").iterdir():
        try:
            stat = (entry / "stat").read_text()
            cmd = (entry / "cmdline").read_bytes()
        except (OSError, ValueError):
            continue
        if stat.rsplit(")", 1)[1].split()[1] == str(pid) and needle in cmd:
            out.append(int(entry.name))
    return out


def _one_line(text: str) -> str:
    lines = [ln for ln in text.splitlines() if ln.strip()]
    assert len(lines) == 1, text
    assert "Traceback" not in text
    return lines[0]


@pytest.mark.parametrize("command", [CHECK, ["bench", "robot", *CHECK[2:]]], ids=["check", "bench"])
@pytest.mark.parametrize("mode", ["silent", "junk"])
def test_a_listener_that_is_not_a_franka_is_one_line_and_status_2(
    listener: Callable[[str], int], mode: str, command: list[str]
) -> None:
    listener(mode)
    res = runner.invoke(app, [*command, "--connect-timeout", "1"])
    assert res.exit_code == 2, res.output
    line = _one_line(res.output)
    assert "cannot connect to the Franka at 127.0.0.1: no answer within 1 s" in line
    assert "check the address" in line
    assert _children(os.getpid()) == []


def test_a_refused_port_is_one_line_and_status_2(robot_port: int) -> None:
    res = runner.invoke(app, CHECK)
    assert res.exit_code == 2, res.output
    assert "at 127.0.0.1: libfranka: Connection to FCI refused" in _one_line(res.output)


def test_a_run_on_a_silent_robot_is_refused_before_it_starts(
    listener: Callable[[str], int], tmp_path: Path
) -> None:
    listener("silent")
    log = tmp_path / "k.h5"
    args = ["skill", "run", "--robot", "franka", "--host", "127.0.0.1", "--no-realtime"]
    res = runner.invoke(app, [*args, "--log", str(log)])
    assert res.exit_code == 2, res.output
    assert "cannot connect to the Franka at 127.0.0.1: no answer within" in _one_line(res.output)
    assert not log.exists() and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("sig", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_ctrl_c_and_sigterm_end_a_hanging_connect(
    listener: Callable[[str], int], sig: signal.Signals, status: int
) -> None:
    listener("silent")
    code = "from teachfit.cli import main; main()"
    proc = subprocess.Popen(
        [sys.executable, "-c", code, *CHECK, "--connect-timeout", "300"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=ENV,
        # a terminal's SIGINT handling (a shell without job control would ignore it)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    probes: list[int] = []
    try:
        while not probes and proc.poll() is None:  # the CLI starts, then waits on its probe
            probes = _children(proc.pid)
            threading.Event().wait(0.05)
        proc.send_signal(sig)
        out, _ = proc.communicate(timeout=120)  # not honoured: waits the 300 s and fails
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert probes and proc.returncode == status, out
    assert "at 127.0.0.1" in _one_line(out)
    assert not any(Path(f"/proc/{pid}").exists() for pid in probes)  # no probe left


def test_a_simulator_that_dies_mid_run_keeps_the_finished_executions(
    franka_sim: SimServer, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from teachfit.execution.skill_trial import SkillTrial

    run = SkillTrial.run

    def run_then_die(self: SkillTrial, *args: object) -> object:
        result = run(self, *args)
        franka_sim.kill()  # the robot vanishes after one execution
        return result

    monkeypatch.setattr(SkillTrial, "run", run_then_die)
    log = tmp_path / "k.h5"
    args = ["skill", "run", "--robot", "franka", "--host", "127.0.0.1", "--no-realtime"]
    try:
        res = runner.invoke(app, [*args, "--starts", "3", "--log", str(log)])
    finally:
        franka_sim.start()
    assert res.exit_code == 1, res.output
    assert "Traceback" not in res.output
    assert "stopped after 1 of 3 execution(s)" in res.output and "127.0.0.1" in res.output
    assert len(read_run_log(log).episodes) == 1
    assert [p.name for p in tmp_path.iterdir()] == ["k.h5"]
    assert _children(os.getpid()) == []


def test_the_simulator_on_a_taken_port_is_one_line_and_status_2(
    listener: Callable[[str], int],
) -> None:
    listener("silent")
    out = subprocess.run(
        [sys.executable, "-m", "teachfit.robot.franka.sim"],
        capture_output=True,
        text=True,
        env=ENV,
        timeout=120,
    )
    assert out.returncode == 2 and out.stdout == ""
    line = _one_line(out.stderr)
    assert "127.0.0.1:1337 is taken" in line and "stop it" in line
