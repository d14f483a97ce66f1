"""Connecting to a Franka within a bounded time, and abandonably.

``pylibfranka.Robot(host)`` holds the GIL while it connects, and its handshake waits for the
robot's answer without a timeout: against a listener that accepts and stays silent, or that
sends something other than libfranka's protocol, it never returns, and Ctrl-C and SIGTERM wait
with it (Python runs signal handlers only between bytecodes of the main thread). A thread
cannot bound it (the GIL is held), so :func:`probe` runs the same connect and one state read in
a child process in its own process group and waits at most ``timeout`` s for it, interruptibly:
the child is killed by its PID at the timeout, on Ctrl-C or SIGTERM, and on any other way out
(and ends itself a second after the timeout, or when this process dies, should an interrupt
come while it is being started). The driver connects in its own process only after the probe
was answered.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys

from teachfit.core.errors import ConnectionLost

#: seconds a connect may take before the robot counts as not answering (a Franka or the
#: simulator answers within milliseconds)
CONNECT_TIMEOUT = 5.0

# the child: connect as the driver does, read one state, print what failed on one line. It
# ends itself too: SIGKILL when its parent dies (Linux), SIGALRM's default action (the
# process ends even while libfranka holds the GIL) a second after the parent's timeout
_CHILD = """
import signal, sys
try:
    import ctypes
    ctypes.CDLL(None).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
except (OSError, AttributeError):
    pass
signal.alarm(int(sys.argv[2]))
try:
    import pylibfranka as pf
    robot = pf.Robot(sys.argv[1], pf.RealtimeConfig.kIgnore)
    robot.read_once()
except BaseException as exc:
    print(" ".join(str(exc).split()) or type(exc).__name__, flush=True)
    sys.exit(1)
"""


def _kill(proc: subprocess.Popen[str]) -> None:
    """Kill the probe's process group (by its PID) and reap it."""
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    proc.wait()
    if proc.stdout is not None:
        proc.stdout.close()


def probe(host: str, timeout: float = CONNECT_TIMEOUT) -> None:
    """Check that a Franka (or the simulator) at ``host`` answers libfranka's connect and
    sends a state within ``timeout`` s (wall clock).

    Raises
    ------
    ConnectionLost
        Naming ``host``: the connect was refused or failed (libfranka's reason), or nothing
        answered in time (a silent or foreign listener, an unreachable address).
    KeyboardInterrupt, SystemExit
        Ctrl-C or SIGTERM while waiting; the child is killed first.
    """
    if not timeout > 0:
        raise ConnectionLost(f"connect timeout must be > 0 s, got {timeout}")
    proc = subprocess.Popen(
        [sys.executable, "-c", _CHILD, host, str(math.ceil(timeout) + 1)],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # its own group: a terminal's Ctrl-C is ours to act on
    )
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        raise ConnectionLost(
            f"cannot connect to the Franka at {host}: no answer within {timeout:g} s (something "
            "there accepts the connection but does not speak libfranka's protocol, or the "
            "address is unreachable): check the address, that FCI is enabled in Desk, or start "
            "the simulator with python -m teachfit.robot.franka.sim"
        ) from None
    finally:
        _kill(proc)
    if proc.returncode != 0:
        lines = [ln for ln in out.splitlines() if ln.strip()]
        why = lines[-1] if lines else f"the connect failed (status {proc.returncode})"
        raise ConnectionLost(f"cannot connect to the Franka at {host}: {why}")
