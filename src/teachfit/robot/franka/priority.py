"""The control thread's scheduling class: ``SCHED_FIFO`` at the highest priority, as libfranka's.

libfranka's callback loop (``Robot::control``) puts its thread in ``SCHED_FIFO`` at
``sched_get_priority_max(SCHED_FIFO)`` when the robot enforces real time
(``RealtimeConfig::kEnforce``), so that no ordinary process preempts a tick. Its active-control
interface (``startTorqueControl`` -> ``readOnce``/``writeOnce``), the one pylibfranka exposes and
the driver uses, does not: the thread that reads and writes keeps the class it was started
with, ``SCHED_OTHER``, even on a real-time kernel. The driver's control thread therefore sets
its own class here, the first thing it does.

A real-time class needs the permission for it: ``CAP_SYS_NICE``, or an ``RLIMIT_RTPRIO`` soft
limit at least as high as the priority (libfranka's installation guide gives a ``realtime``
group ``rtprio 99`` in ``/etc/security/limits.conf``). Without either, :func:`to_fifo` says why
and the thread keeps its class; with only a lower limit it takes that priority.

On Linux ``sched_setscheduler(0, ...)`` sets the *calling thread's* class, not the process's:
the caller's other threads keep theirs. pylibfranka's ``Robot()`` constructor moves the thread
that calls it to ``SCHED_FIFO`` 99 where the process may (measured with pylibfranka 0.21.3):
in the driver that is the caller's thread, which runs the skill engine. The driver leaves it
there while connected: with only the control thread real-time, the engine, sharing the GIL
with it, fell behind the loop, and on the twin every peg2d approach timed out (0/3 against 3/3
with both real-time). :func:`restore` puts the caller back when the driver closes.
"""

from __future__ import annotations

import os
import resource
import threading
from dataclasses import dataclass

#: how to allow the class, as :class:`ThreadClass` ``why`` and the driver's errors say it
PERMISSION_FIX = (
    "give the process CAP_SYS_NICE, or an rtprio limit of 99 (libfranka's real-time set-up: "
    "'@realtime - rtprio 99' in /etc/security/limits.conf and the user in group realtime)"
)


@dataclass(frozen=True)
class ThreadClass:
    """A thread's scheduling class: ``policy`` (``"SCHED_FIFO"`` or ``"SCHED_OTHER"``),
    ``priority`` (1-99 for ``SCHED_FIFO``, 0 otherwise) and ``why`` it is not ``SCHED_FIFO``
    (empty when it is)."""

    policy: str
    priority: int = 0
    why: str = ""

    @property
    def realtime(self) -> bool:
        return self.policy == "SCHED_FIFO"

    def describe(self) -> str:
        """``"SCHED_FIFO 99"``, or ``"SCHED_OTHER (why)"``."""
        if self.realtime:
            return f"{self.policy} {self.priority}"
        return f"{self.policy} ({self.why})" if self.why else self.policy


def _priorities() -> list[int]:
    """The priorities to try, highest first: the policy's maximum, then the rtprio soft limit
    when it is lower (an unprivileged process may use up to its limit)."""
    top = os.sched_get_priority_max(os.SCHED_FIFO)
    soft = resource.getrlimit(resource.RLIMIT_RTPRIO)[0]
    limit = top if soft == resource.RLIM_INFINITY else int(soft)
    return [top] + ([limit] if 0 < limit < top else [])


def to_fifo() -> ThreadClass:
    """Put the calling thread in ``SCHED_FIFO`` at the highest priority it is allowed; the
    class it ends in (``SCHED_OTHER`` with the reason when none is allowed)."""
    if not hasattr(os, "sched_setscheduler"):
        return ThreadClass("SCHED_OTHER", why="this operating system has no SCHED_FIFO")
    for prio in _priorities():
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(prio))
        except PermissionError:
            continue
        return ThreadClass("SCHED_FIFO", prio)
    return ThreadClass("SCHED_OTHER", why=f"SCHED_FIFO not permitted: {PERMISSION_FIX}")


def probe() -> ThreadClass:
    """The class :func:`to_fifo` would give a new thread, found by a throw-away thread (the
    calling thread's class is left as it is)."""
    got: list[ThreadClass] = []
    thread = threading.Thread(target=lambda: got.append(to_fifo()), name="fifo-probe")
    thread.start()
    thread.join()
    return got[0]


def current() -> tuple[int, os.sched_param] | None:
    """The calling thread's policy and parameters, for :func:`restore` (None: no such API)."""
    if not hasattr(os, "sched_getscheduler"):
        return None
    return os.sched_getscheduler(0), os.sched_getparam(0)


def restore(saved: tuple[int, os.sched_param] | None) -> None:
    """Put the calling thread back in the class :func:`current` saved."""
    if saved is None or (os.sched_getscheduler(0), os.sched_getparam(0)) == saved:
        return
    try:
        os.sched_setscheduler(0, *saved)
    except PermissionError:  # only ever lowers the class here, which Linux allows
        pass
