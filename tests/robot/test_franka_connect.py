"""Connecting to a Franka is bounded and abandonable (``robot.franka.connect``), and the
simulator refuses to start on a taken port in one line (``robot.franka.sim``).

The listeners are the test's own processes on 127.0.0.1:1337 (libfranka's port), stopped by
their PID after each test; the session's simulator is stopped meanwhile (``robot_port``)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path

import pytest

pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")

from teachfit.core.errors import ConnectionLost  # noqa: E402
from teachfit.robot.franka.connect import probe  # noqa: E402


def probe_children() -> list[int]:
    """PIDs of this process's children that run a connect probe."""
    me, out = str(os.getpid()), []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmd = (entry / "cmdline").read_bytes()
        except OSError:
            continue
        if stat.rsplit(")", 1)[1].split()[1] == me and b"pylibfranka" in cmd:
            out.append(int(entry.name))
    return out


@pytest.mark.parametrize("mode", ["silent", "junk"])
def test_a_listener_that_does_not_answer_is_a_lost_connection_naming_the_host(
    listener: Callable[[str], int], mode: str
) -> None:
    listener(mode)
    with pytest.raises(ConnectionLost) as err:
        probe("127.0.0.1", timeout=1.0)
    text = str(err.value)
    assert text.startswith("cannot connect to the Franka at 127.0.0.1: no answer within 1 s")
    assert "\n" not in text and "check the address" in text
    assert probe_children() == []  # the blocked connect was killed and reaped


def test_a_refused_connect_says_so_at_once(robot_port: int) -> None:
    with pytest.raises(ConnectionLost, match=r"at 127\.0\.0\.1: libfranka: Connection .*refused"):
        probe("127.0.0.1", timeout=60.0)
    assert probe_children() == []


def test_ctrl_c_abandons_a_connect_that_hangs(
    listener: Callable[[str], int], ctrl_c: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    listener("silent")
    waiting, seen = threading.Event(), []
    communicate = subprocess.Popen.communicate

    def spy(self: subprocess.Popen[str], *args: object, **kw: object) -> object:
        waiting.set()  # the probe started and waits for its child
        return communicate(self, *args, **kw)

    def interrupt() -> None:  # then Ctrl-C, as a user would press it
        if waiting.wait(60):
            seen.extend(probe_children())
            os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(subprocess.Popen, "communicate", spy)
    thread = threading.Thread(target=interrupt, daemon=True)
    thread.start()
    with pytest.raises(KeyboardInterrupt):
        probe("127.0.0.1", timeout=120.0)  # not interrupted: a ConnectionLost after 120 s
    thread.join(10)
    assert seen and probe_children() == []
    assert not any(Path(f"/proc/{pid}").exists() for pid in seen)  # killed and reaped


def test_the_driver_connects_with_the_bound(listener: Callable[[str], int]) -> None:
    from teachfit.robot.franka.driver import FrankaParams, FrankaRobot

    listener("silent")
    before = sys.getswitchinterval()
    with pytest.raises(ConnectionLost, match="no answer within 0.5 s"):
        FrankaRobot("127.0.0.1", params=FrankaParams(connect_timeout=0.5), realtime=False)
    assert sys.getswitchinterval() == before  # nothing of the driver stays behind


def test_the_simulator_on_a_taken_port_is_one_line_and_status_2(
    listener: Callable[[str], int], capsys: pytest.CaptureFixture[str]
) -> None:
    from teachfit.robot.franka.sim import main

    listener("silent")
    with pytest.raises(SystemExit) as err:
        main([])
    assert err.value.code == 2
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and "127.0.0.1:1337 is taken" in lines[0] and "stop it" in lines[0]


def test_a_lost_connection_names_the_robot_and_the_fix() -> None:
    import pylibfranka as pf

    from teachfit.robot.franka.loop import fault_from

    lost = fault_from(pf.NetworkException("libfranka: UDP receive: Timeout"), "the Franka at H")
    assert isinstance(lost, ConnectionLost)
    assert str(lost).startswith("lost the connection to the Franka at H (NetworkException: ")
    assert "check that it is on and reachable" in str(lost)
