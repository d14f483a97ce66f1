"""A local Ray instance is confined to this machine and to its driver: every process of it
listens on a loopback address only, and ``kill -9`` of the driver ends all of them (skipped
without ray)."""

from __future__ import annotations

import ipaddress
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

import teachfit

from .test_ray_runner import _session  # live PIDs whose sid (see setsid(2)) is the one given

pytest.importorskip("ray")

SRC = str(Path(teachfit.__file__).resolve().parents[1])
DRIVER = Path(__file__).with_name("ray_local_driver.py")


def _address(hex_addr: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address:
    """An address of ``/proc/net/tcp{,6}``: 32-bit words in host byte order."""
    raw = bytes.fromhex(hex_addr)
    if sys.byteorder == "little":
        raw = b"".join(raw[i : i + 4][::-1] for i in range(0, len(raw), 4))
    family = socket.AF_INET6 if len(raw) == 16 else socket.AF_INET
    return ipaddress.ip_address(socket.inet_ntop(family, raw))


def _listening(pids: list[int]) -> list[tuple[int, str]]:
    """``(pid, address)`` of every TCP socket in state LISTEN that one of ``pids`` holds."""
    listen: dict[str, str] = {}
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with open(table) as fh:
            for line in fh.readlines()[1:]:
                cols = line.split()
                if cols[3] == "0A":  # TCP_LISTEN
                    host, _, port = cols[1].partition(":")
                    listen[cols[9]] = f"{_address(host)}:{int(port, 16)}"
    out = []
    for pid in pids:
        try:
            fds = os.listdir(f"/proc/{pid}/fd")
        except OSError:
            continue
        for fd in fds:
            try:
                link = os.readlink(f"/proc/{pid}/fd/{fd}")
            except OSError:
                continue
            if link.startswith("socket:[") and link[8:-1] in listen:
                out.append((pid, listen[link[8:-1]]))
    return out


def _loopback(address: str) -> bool:
    ip = ipaddress.ip_address(address.rpartition(":")[0])
    mapped = getattr(ip, "ipv4_mapped", None)
    return ip.is_loopback or (mapped is not None and mapped.is_loopback)


def test_a_local_instance_listens_on_loopback_and_dies_with_its_driver(tmp_path: Path) -> None:
    proc = subprocess.Popen(
        [sys.executable, str(DRIVER), str(tmp_path / "s.db")],
        env=dict(os.environ, PYTHONPATH=SRC),
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        start_new_session=True,  # the driver and every process it starts share its sid
    )
    sid = proc.pid
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()  # the first trial stored: the instance runs
        assert line.startswith("stored"), f"the driver ended: {line!r}"
        pids = _session(sid)
        names = {open(f"/proc/{p}/comm").read().strip() for p in pids}
        assert {"gcs_server", "raylet"} <= names, names
        listeners = _listening(pids)
        assert len(listeners) >= 3, listeners  # at least the GCS, the raylet, the driver
        assert [x for x in listeners if not _loopback(x[1])] == []
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        # Ray alone leaves the raylet's agents for 60 s or more (they wait for the dead GCS);
        # this bounds the wait, it does not time it
        deadline = time.monotonic() + 20
        while _session(sid) and time.monotonic() < deadline:
            time.sleep(0.2)
        left = {
            p: open(f"/proc/{p}/cmdline").read().replace("\0", " ")[:80].strip()
            for p in _session(sid)
        }
        assert left == {}, left
    finally:
        for pid in _session(sid):  # only what the driver started
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
