"""The control thread's scheduling class (SCHED_FIFO, as libfranka's own loop sets it)."""

from __future__ import annotations

import os
import sys

import pytest

from teachfit.core.errors import RobotFault
from teachfit.robot.franka import priority
from teachfit.robot.franka.priority import ThreadClass, probe, to_fifo

linux = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="SCHED_FIFO is Linux's")


def _refuse(*_args: object) -> None:
    raise PermissionError(1, "Operation not permitted")


@linux
def test_the_probe_leaves_the_callers_class_and_says_what_a_thread_gets() -> None:
    before = os.sched_getscheduler(0)
    got = probe()
    assert os.sched_getscheduler(0) == before  # only the throw-away thread changed
    if got.realtime:
        assert got.priority == os.sched_get_priority_max(os.SCHED_FIFO)
        assert got.describe() == f"SCHED_FIFO {got.priority}"
    else:
        assert "CAP_SYS_NICE" in got.why and got.describe().startswith("SCHED_OTHER (")


@linux
def test_a_refused_class_keeps_the_thread_as_it_was_and_names_the_fix(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(priority.os, "sched_setscheduler", _refuse)
    got = to_fifo()
    assert got == ThreadClass("SCHED_OTHER", why=got.why) and not got.realtime
    assert "rtprio 99" in got.why and "/etc/security/limits.conf" in got.why


@linux
def test_a_lower_rtprio_limit_is_the_priority_taken(monkeypatch: pytest.MonkeyPatch) -> None:
    asked: list[int] = []

    def only_up_to_40(_pid: int, _policy: int, param: os.sched_param) -> None:
        asked.append(param.sched_priority)
        if param.sched_priority > 40:
            raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr(priority.os, "sched_setscheduler", only_up_to_40)
    monkeypatch.setattr(priority.resource, "getrlimit", lambda _which: (40, 40))
    assert to_fifo() == ThreadClass("SCHED_FIFO", 40)
    assert asked == [os.sched_get_priority_max(os.SCHED_FIFO), 40]


@linux
def test_the_control_thread_runs_in_fifo_where_allowed_the_caller_until_close(
    franka_sim: object,
) -> None:
    pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")
    from teachfit.robot.franka.driver import FrankaRobot

    allowed = probe()
    caller = os.sched_getscheduler(0)
    with FrankaRobot("127.0.0.1", realtime=False) as robot:
        robot.step(20)
        thread = robot._loop._thread
        assert thread is not None and thread.native_id is not None
        expected = os.SCHED_FIFO if allowed.realtime else caller
        assert os.sched_getscheduler(thread.native_id) == expected
        assert robot.thread_class == allowed
        # pylibfranka's Robot() moves its caller to SCHED_FIFO where allowed, and the driver
        # leaves it there (the skill engine keeps pace with the loop) until close
        assert os.sched_getscheduler(0) == expected
    assert os.sched_getscheduler(0) == caller


@linux
def test_a_refused_class_stops_the_driver_before_it_connects(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")
    from teachfit.robot.franka.driver import FrankaParams, FrankaRobot

    monkeypatch.setattr(priority.os, "sched_setscheduler", _refuse)
    # nothing listens at this address: the refusal comes first, not a connection timeout
    with pytest.raises(RobotFault, match="may not run in SCHED_FIFO.*CAP_SYS_NICE"):
        FrankaRobot("127.0.0.9", params=FrankaParams(connect_timeout=30.0), realtime=True)
