"""Child processes that end with their parent (Linux ``prctl(PR_SET_PDEATHSIG)``).

A worker or a simulator started by teachfit must not outlive the process that started it, even
when that one is killed with SIGKILL and runs no clean-up: the kernel then signals the child.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal

_PR_SET_PDEATHSIG = 1


def die_with_parent(parent: int | None = None, sig: int = signal.SIGKILL) -> bool:
    """Have the kernel send ``sig`` to this process when its parent dies; exit at once if
    ``parent`` (the expected parent PID) is already gone. False where unsupported."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        ok = libc.prctl(_PR_SET_PDEATHSIG, int(sig), 0, 0, 0) == 0
    except (OSError, AttributeError):
        ok = False
    if parent is not None and os.getppid() != parent:
        os._exit(1)  # the parent died before the request took effect
    return ok
