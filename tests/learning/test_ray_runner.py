"""Trials on an existing multi-node Ray cluster: ``learn skill --ray`` and ``bench learning
--ray --scaling`` (a head and two worker nodes on 127.0.0.1, started and stopped by PID)."""

from __future__ import annotations

import os
import re
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

import teachfit

from .conftest import free_port

ray = pytest.importorskip("ray")

SRC = str(Path(teachfit.__file__).resolve().parents[1])
RAY = Path(sys.executable).with_name("ray")


def _session(sid: int) -> list[int]:
    """PIDs of the processes in session ``sid`` (the nodes run in sessions of their own)."""
    out = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    fields = fh.read().rpartition(")")[2].split()
            except OSError:
                continue
            if int(fields[3]) == sid and fields[0] != "Z":
                out.append(int(entry))
    return out


def _reset_ray_token_cache() -> None:
    loader = getattr(ray._raylet, "AuthenticationTokenLoader", None)  # Ray >= 2.52
    if loader is not None:
        loader.instance().reset_cache()


@contextmanager
def ray_cluster(workers: int = 2, cpus: int = 1) -> Iterator[str]:
    """A head and ``workers`` worker nodes, ``cpus`` CPUs each, on 127.0.0.1; yields the
    address. Each ``ray start --block`` runs in a session of its own; stopping sends it
    SIGTERM by PID and then SIGKILLs whatever is left of that session, by PID. The cluster
    has a token of its own (``RAY_AUTH_TOKEN``, set here for this process too), not the
    ``~/.ray/auth_token`` that other Ray users of this machine share and may replace."""
    tmp = tempfile.mkdtemp(prefix="tfray")  # short: Ray's socket paths must fit 107 bytes
    os.environ["RAY_AUTH_MODE"] = "token"
    os.environ["RAY_AUTH_TOKEN"] = secrets.token_hex(32)
    _reset_ray_token_cache()
    env = dict(os.environ, PYTHONPATH=SRC, RAY_USAGE_STATS_ENABLED="0")
    port = free_port()
    address = f"127.0.0.1:{port}"
    nodes: list[subprocess.Popen[bytes]] = []
    ok = False

    def start(*args: str) -> None:
        ports = {
            "--node-manager-port": free_port(),
            "--object-manager-port": free_port(),
            "--metrics-export-port": free_port(),
            "--dashboard-agent-listen-port": free_port(),
            "--dashboard-agent-grpc-port": free_port(),
            "--runtime-env-agent-port": free_port(),
        }
        cmd = [str(RAY), "start", "--block", "--node-ip-address", "127.0.0.1"]
        cmd += ["--num-cpus", str(cpus), "--disable-usage-stats", *args]
        cmd += [x for k, v in ports.items() for x in (k, str(v))]
        log = open(Path(tmp) / f"node{len(nodes)}.log", "wb")  # noqa: SIM115
        nodes.append(
            subprocess.Popen(
                cmd, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True
            )
        )

    try:
        start(
            "--head",
            "--port",
            str(port),
            "--include-dashboard",
            "false",
            "--temp-dir",
            tmp,
        )
        deadline = time.monotonic() + 120
        while True:  # the head's GCS must listen before the worker nodes join it
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                if nodes[0].poll() is not None or time.monotonic() > deadline:
                    log = (Path(tmp) / "node0.log").read_text()[-3000:]
                    pytest.fail(f"the Ray head did not start: {log}")
                time.sleep(0.2)
        sockets = Path(tmp, "session_latest", "sockets")
        for k in range(1, workers + 1):
            # one at a time: nodes of one machine pick their socket names (raylet.k,
            # plasma_store.k) by what exists, and two starting together take the same one
            start("--address", address)
            deadline = time.monotonic() + 120
            while len([*sockets.glob("raylet*")]) <= k or len([*sockets.glob("plasma*")]) <= k:
                if nodes[-1].poll() is not None or time.monotonic() > deadline:
                    log = (Path(tmp) / f"node{k}.log").read_text()[-3000:]
                    pytest.fail(f"Ray worker node {k} did not start: {log}")
                time.sleep(0.2)
        yield address
        ok = True
    finally:
        for node in reversed(nodes):
            node.send_signal(signal.SIGTERM)
        deadline = time.monotonic() + 20
        for node in nodes:
            try:
                node.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                node.kill()
                node.wait()
        time.sleep(0.5)
        left = [pid for node in nodes for pid in _session(node.pid)]
        for pid in left:  # only processes of the sessions started here
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        os.environ.pop("RAY_AUTH_MODE", None)
        os.environ.pop("RAY_AUTH_TOKEN", None)
        _reset_ray_token_cache()
        print(f"\nRay cluster stopped by PID: {len(left)} process(es) needed SIGKILL")
        if ok:
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            print(f"node logs kept in {tmp}")


@pytest.mark.cluster
@pytest.mark.skipif(
    os.environ.get("TEACHFIT_RAY_CLUSTER") != "1",
    reason="opt-in (TEACHFIT_RAY_CLUSTER=1): Ray nodes listen on the machine's own interface "
    "address, not loopback alone, and a 3-node start takes 45-160 s on 2 busy cores",
)
def test_learn_skill_and_bench_scaling_on_a_three_node_cluster(tmp_path: Path) -> None:
    with ray_cluster(workers=2, cpus=1) as address:
        proc = subprocess.run(
            [sys.executable, str(Path(__file__).with_name("ray_driver.py")), address, tmp_path],
            env=dict(os.environ, PYTHONPATH=SRC, COLUMNS="200"),
            capture_output=True,
            text=True,
            timeout=400,
        )
    out = proc.stdout
    print(out)
    assert proc.returncode == 0, out + proc.stderr[-3000:]
    assert "nodes alive: 3" in out
    # 6 trials, 3 at once, one CPU each: every node ran some; the driver disconnected again
    assert "trials: finished 6 stored 6 unique 6 nodes 3 connected-after False" in out
    assert "learn skill exit 0" in out and f"Ray at {address}" in out
    assert "study holds 3" in out
    assert "bench scaling exit 0" in out
    table = out.partition("bench scaling")[2]
    rows = re.findall(r"^\s*(\d+)\s+(\d+)\s+[\d.]+\s+([\d.]+)\s+x[\d.]+\s+[\d.]+\s*$", table, re.M)
    assert [(w, n) for w, n, _ in rows] == [("1", "1"), ("2", "2")], out  # workers, trials
    assert all(float(tps) > 0 for _, _, tps in rows)
