"""The libfranka-protocol simulator the Franka driver tests run against.

franky-sim (MuJoCo FR3) is started once per session through teachfit's loopback launcher
(``python -m teachfit.robot.franka.sim``: every socket on 127.0.0.1) as a separate process in its
own process group, and stopped by its PID and group at the end. Tests that need it are skipped
when the ``franka`` extra (pylibfranka, franky-sim) is not installed.
"""

from __future__ import annotations

import fcntl
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def push_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """File through which a test pushes the simulated hand (``fx fy fz`` N, base frame)."""
    return tmp_path_factory.mktemp("franky_sim") / "push.txt"


@pytest.fixture(scope="session")
def franka_sim(push_file: Path) -> Iterator[object]:
    """A running franky-sim on 127.0.0.1 (port 1337); yields the :class:`SimServer`."""
    pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")
    pytest.importorskip("franky_sim", reason="needs the franka extra (franky-sim)")
    from teachfit.robot.franka.sim import SimServer

    # one franky-sim per machine (its port 1337 is fixed): a pytest-xdist worker holds this
    # machine-wide lock while its server runs, and another worker's first franka test waits
    lock = (Path(tempfile.gettempdir()) / "teachfit-franky-sim.lock").open("w")
    fcntl.flock(lock, fcntl.LOCK_EX)
    try:
        server = SimServer(push_file=push_file).start()
        try:
            yield server
        finally:
            server.stop()
    finally:
        fcntl.flock(lock, fcntl.LOCK_UN)
        lock.close()


@pytest.fixture
def expected_tcp(franka_sim: object) -> Callable[[object], object]:
    """``f(frames) -> (3, 4)``: the TCP pose (world) computed from a plain pylibfranka read of
    ``O_T_EE`` (taken before a driver connects), ``base2world @ O_T_EE @ ee2tcp``."""
    import numpy as np
    import pylibfranka as pf

    def tcp(frames: object) -> object:
        raw = pf.Robot("127.0.0.1", pf.RealtimeConfig.kIgnore)
        o_t_ee = np.asarray(raw.read_once().O_T_EE).reshape(4, 4, order="F")
        del raw
        b2w, e2t = frames.matrices()  # type: ignore[attr-defined]
        return (b2w @ o_t_ee @ e2t)[:3]

    return tcp


@pytest.fixture
def ctrl_c() -> Iterator[None]:
    """Python's own SIGINT handler (KeyboardInterrupt) for the test, as at a terminal.

    A process started in the background of a shell without job control (a CI runner's, or
    ``cmd &`` in a script) inherits SIGINT *ignored*, and Python then leaves it ignored: a
    test that sends itself SIGINT would wait for an interrupt that never comes."""
    import signal

    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
