"""The franky-sim launcher: every socket of the simulator process is on 127.0.0.1."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")


def _socket_addresses(pid: int) -> list[tuple[str, str, int]]:
    """``(kind, local ip, port)`` of every IPv4/IPv6 socket process ``pid`` holds (/proc)."""
    inodes = set()
    for fd in os.listdir(f"/proc/{pid}/fd"):
        try:
            link = os.readlink(f"/proc/{pid}/fd/{fd}")
        except OSError:
            continue
        if link.startswith("socket:["):
            inodes.add(link[8:-1])
    out = []
    for kind in ("tcp", "udp", "tcp6", "udp6"):
        lines = Path(f"/proc/{pid}/net/{kind}").read_text().splitlines()[1:]
        for line in lines:
            cols = line.split()
            if cols[9] not in inodes:
                continue
            hex_ip, hex_port = cols[1].split(":")
            if len(hex_ip) == 8:
                ip = ".".join(str(int(hex_ip[i : i + 2], 16)) for i in (6, 4, 2, 0))
            else:
                ip = hex_ip
            out.append((kind, ip, int(hex_port, 16)))
    return out


def test_simulator_sockets_are_loopback_only_while_a_client_is_connected(
    franka_sim: object,
) -> None:
    from teachfit.robot.franka.driver import FrankaRobot

    pid = franka_sim.pid  # type: ignore[attr-defined]
    with FrankaRobot("127.0.0.1", realtime=False) as robot:
        robot.step(20)  # the UDP state socket exists once a client connected
        addresses = _socket_addresses(pid)
    kinds = {k for k, _, _ in addresses}
    assert "udp" in kinds and "tcp" in kinds, addresses
    assert {ip for _, ip, _ in addresses} == {"127.0.0.1"}, addresses
    assert (("tcp", "127.0.0.1", 1337)) in addresses


def test_launcher_patch_rewrites_all_interfaces_and_refuses_others() -> None:
    code = (
        "import socket\n"
        "from teachfit.robot.franka.sim import confine_to_loopback\n"
        "confine_to_loopback()\n"
        "s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(('0.0.0.0', 0))\n"
        "print(s.getsockname()[0])\n"
        "t = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)\n"
        "try:\n"
        "    t.bind(('10.11.12.13', 0))\n"
        "except OSError as e:\n"
        "    print('refused', 'not loopback' in str(e))\n"
    )
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2] / "src")}
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["127.0.0.1", "refused", "True"]


def test_a_second_server_is_refused_while_the_port_is_taken(franka_sim: object) -> None:
    from teachfit.core.errors import ConnectionLost
    from teachfit.robot.franka.sim import SimServer

    second = SimServer()
    with pytest.raises(ConnectionLost, match="taken"):
        second.start()
    assert second.pid is None  # nothing was started


def _running(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie, ended and waiting to be reaped, does not)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except (FileNotFoundError, IndexError):
        return False


def test_a_simulator_ends_with_the_process_that_started_it_even_when_killed(
    robot_port: int,
) -> None:
    """The starter SIGKILLed (no clean-up runs): the kernel stops its simulator, no orphan."""
    import time

    code = (
        "import time\nfrom teachfit.robot.franka.sim import SimServer\n"
        "s = SimServer().start()\nprint(s.pid, flush=True)\ntime.sleep(600)\n"
    )
    starter = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert starter.stdout is not None
    sim_pid = int(starter.stdout.readline())
    assert _running(sim_pid)
    starter.kill()
    starter.wait()
    from teachfit.robot.franka.sim import HOST, ROBOT_PORT, port_free

    deadline = time.monotonic() + 30
    while (_running(sim_pid) or not port_free(HOST, ROBOT_PORT)) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not _running(sim_pid), "the simulator outlived the process that started it"
    assert port_free(HOST, ROBOT_PORT)
