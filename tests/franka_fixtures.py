"""The libfranka-protocol simulator and the robot's port, for every test that needs them.

franky-sim (MuJoCo FR3) is started once per run through teachfit's loopback launcher
(``python -m teachfit.robot.franka.sim``: every socket on 127.0.0.1) as a separate process in its
own process group, and stopped by its PID and group at the end. libfranka's port (1337) cannot
be changed, so one test process at a time owns it (a machine-wide lock, for pytest-xdist
workers): the simulator, or a test's own listener there (:func:`robot_port`, which stops the
simulator for the test; the next test that needs it starts it again). Tests that need the
simulator are skipped when the ``franka`` extra (pylibfranka, franky-sim) is not installed.

The fixtures are registered once, by the top ``tests/conftest.py``: a second registration would
start a second simulator that waits for the lock the first one holds.
"""

from __future__ import annotations

import fcntl
import os
import signal
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from teachfit.robot.franka.sim import ROBOT_PORT, SimServer

if TYPE_CHECKING:
    from teachfit.robot.franka.frames import FrankaFrames


@pytest.fixture(scope="session")
def push_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """File through which a test pushes the simulated hand (``fx fy fz`` N, base frame)."""
    return tmp_path_factory.mktemp("franky_sim") / "push.txt"


@pytest.fixture(scope="session")
def franka_port(push_file: Path) -> Iterator[SimServer]:
    """The machine-wide hold on 127.0.0.1:1337; yields the (not yet started)
    :class:`~teachfit.robot.franka.sim.SimServer` that runs there, stopped at the end."""
    pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")
    pytest.importorskip("franky_sim", reason="needs the franka extra (franky-sim)")
    # one franky-sim per machine (its port 1337 is fixed): a pytest-xdist worker holds this
    # machine-wide lock while it owns the port, and another worker's first franka test waits
    lock = (Path(tempfile.gettempdir()) / "teachfit-franky-sim.lock").open("w")
    fcntl.flock(lock, fcntl.LOCK_EX)
    try:
        server = SimServer(push_file=push_file)
        try:
            yield server
        finally:
            server.stop()
    finally:
        fcntl.flock(lock, fcntl.LOCK_UN)
        lock.close()


@pytest.fixture
def franka_sim(franka_port: SimServer) -> SimServer:
    """A running franky-sim on 127.0.0.1 (port 1337): the :class:`SimServer` (started on
    first use, kept running between tests)."""
    if franka_port.pid is None:
        franka_port.start()
    return franka_port


@pytest.fixture
def robot_port(franka_port: SimServer) -> Iterator[int]:
    """127.0.0.1:1337 free for the test's own listener; yields the port. A running simulator
    is stopped for the test; the next test that needs it starts it again
    (:func:`franka_sim`), so consecutive twin tests pay no simulator start-up."""
    franka_port.stop()
    yield ROBOT_PORT


@pytest.fixture
def franka_twin(robot_port: int) -> Iterator[Callable[..., SimServer]]:
    """``start(start=(dx, dy, dz), realtime=False) -> TwinProcess``: the Franka twin of task
    ``peg`` (``teachfit.robot.franka.twin``; lock-step ``--no-realtime`` unless ``realtime``)
    with its TCP ``start`` (m) from the hole's contact pose, on 127.0.0.1:1337 in its own
    process group, stopped by its PID after the test (franky-sim is stopped for the test,
    :func:`robot_port`)."""
    from teachfit.robot.franka.twin import TwinProcess

    started: list[SimServer] = []

    def start(
        start: tuple[float, float, float] = (0.0, 0.0, 0.05), realtime: bool = False
    ) -> SimServer:
        twin = TwinProcess("peg", realtime=realtime, start=start)
        started.append(twin)
        return twin.start()

    try:
        yield start
    finally:
        for twin in started:
            # at once (SIGKILL to its group: nothing of it is left, its ports are free again at
            # once, SO_REUSEADDR); a graceful stop spends ~0.4 s in the twin's clean-up, which
            # the tests of `robot twin`'s SIGTERM and Ctrl-C check
            twin.kill()
            twin.stop()


#: a listener on 127.0.0.1: ``silent`` accepts and never answers, ``junk`` accepts and sends
#: bytes that are not libfranka's protocol; prints ``ready`` once listening
_LISTENER = """
import socket, sys
mode, port = sys.argv[1], int(sys.argv[2])
server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
server.bind(("127.0.0.1", port))
server.listen(8)
print("ready", flush=True)
held = []
while True:
    conn, _ = server.accept()
    held.append(conn)
    if mode == "junk":
        try:
            conn.sendall(bytes(range(256)) * 64)
        except OSError:
            pass
"""


@pytest.fixture
def listener(robot_port: int) -> Iterator[Callable[[str], int]]:
    """``start(mode) -> pid``: a ``silent`` or ``junk`` listener on 127.0.0.1:1337 in its own
    process (group), stopped by its PID after the test."""
    procs: list[subprocess.Popen[str]] = []

    def start(mode: str) -> int:
        proc = subprocess.Popen(
            [sys.executable, "-c", _LISTENER, mode, str(robot_port)],
            stdout=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        procs.append(proc)
        assert proc.stdout is not None and proc.stdout.readline().strip() == "ready"
        return proc.pid

    try:
        yield start
    finally:
        for proc in procs:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=10)
            assert proc.stdout is not None
            proc.stdout.close()


@pytest.fixture
def expected_tcp(franka_sim: SimServer) -> Callable[[FrankaFrames], object]:
    """``f(frames) -> (3, 4)``: the TCP pose (world) computed from a plain pylibfranka read of
    ``O_T_EE`` (taken before a driver connects), ``base2world @ O_T_EE @ ee2tcp``."""
    import numpy as np
    import pylibfranka as pf

    def tcp(frames: FrankaFrames) -> object:
        raw = pf.Robot("127.0.0.1", pf.RealtimeConfig.kIgnore)
        o_t_ee = np.asarray(raw.read_once().O_T_EE).reshape(4, 4, order="F")
        del raw
        b2w, e2t = frames.matrices()
        return (b2w @ o_t_ee @ e2t)[:3]

    return tcp


@pytest.fixture
def ctrl_c() -> Iterator[None]:
    """Python's own SIGINT handler (KeyboardInterrupt) for the test, as at a terminal.

    A process started in the background of a shell without job control (a CI runner's, or
    ``cmd &`` in a script) inherits SIGINT *ignored*, and Python then leaves it ignored: a
    test that sends itself SIGINT would wait for an interrupt that never comes."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
