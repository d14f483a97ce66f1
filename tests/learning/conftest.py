"""Real servers for the learning tests: a private PostgreSQL cluster on 127.0.0.1.

The server is Debian's ``postgresql`` (``.ci/run`` installs it): ``initdb`` into a temporary
data directory, ``postgres`` on a free port of 127.0.0.1 only (no Unix socket outside the data
directory), stopped by its PID. As root (CI) it runs as the ``postgres`` system user, since
PostgreSQL refuses to run as root. Skipped only when the binaries are absent.
"""

from __future__ import annotations

import glob
import os
import pwd
import random
import shutil
import signal
import socket
import subprocess
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import pytest


def pg_bindir() -> Path | None:
    """Where ``initdb`` and ``postgres`` are: Debian's versioned dir, else the PATH."""
    for d in sorted(glob.glob("/usr/lib/postgresql/*/bin"), reverse=True):
        if Path(d, "initdb").exists() and Path(d, "postgres").exists():
            return Path(d)
    found = shutil.which("initdb")
    if found and shutil.which("postgres"):
        return Path(found).resolve().parent
    return None


_GIVEN: set[int] = set()


def free_port() -> int:
    """A free TCP port below the kernel's ephemeral range (a port picked from that range can
    be taken by some outgoing connection before the server that was meant to bind it does)."""
    rng = random.Random()
    for _ in range(1000):
        port = rng.randrange(20000, 32000)
        if port in _GIVEN:
            continue
        with socket.socket() as s:
            try:
                s.bind(("0.0.0.0", port))
            except OSError:
                continue
        _GIVEN.add(port)
        return port
    raise RuntimeError("no free TCP port in 20000-32000")


def _as_user() -> dict[str, object]:
    """``subprocess`` options running the server as ``postgres`` when we are root."""
    if os.geteuid() != 0:
        return {}
    pw = pwd.getpwnam("postgres")  # created by Debian's postgresql package
    return {"user": pw.pw_uid, "group": pw.pw_gid, "extra_groups": []}


@pytest.fixture(scope="session")
def postgres_url() -> Iterator[str]:
    """An SQLAlchemy URL of an empty database on a private PostgreSQL server."""
    bindir = pg_bindir()
    if bindir is None:
        pytest.skip(
            "PostgreSQL binaries (initdb, postgres) not installed: apt-get install postgresql"
        )
    import psycopg  # the dev extra installs psycopg[binary]: SQLAlchemy's postgresql:// driver

    user = _as_user()
    tmp = Path(tempfile.mkdtemp(prefix="teachfit-pg-"))
    data = tmp / "data"
    data.mkdir()
    if user:
        os.chmod(tmp, 0o755)
        os.chown(data, int(user["user"]), int(user["group"]))  # type: ignore[call-overload]
    subprocess.run(
        [str(bindir / "initdb"), "-D", str(data), "-U", "teachfit", "--auth=trust", "-E", "UTF8"],
        check=True,
        capture_output=True,
        **user,  # type: ignore[arg-type]
    )
    port = free_port()
    log = open(tmp / "server.log", "wb")  # noqa: SIM115 (closed below)
    server = subprocess.Popen(
        [
            str(bindir / "postgres"),
            "-D",
            str(data),
            "-h",
            "127.0.0.1",
            "-p",
            str(port),
            "-k",
            str(data),  # its Unix socket stays in the private data directory
            "-c",
            "fsync=off",
            "-c",
            "max_connections=100",
        ],
        stdout=log,
        stderr=subprocess.STDOUT,
        **user,  # type: ignore[arg-type]
    )
    url = f"postgresql://teachfit@127.0.0.1:{port}/postgres"
    try:
        deadline = time.monotonic() + 30
        while True:
            try:
                psycopg.connect(url).close()
                break
            except psycopg.OperationalError:
                if server.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(
                        f"PostgreSQL did not start: {(tmp / 'server.log').read_text()}"
                    ) from None
                time.sleep(0.1)
        yield url
    finally:
        server.send_signal(signal.SIGINT)  # fast shutdown, by PID
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
        log.close()
        shutil.rmtree(tmp, ignore_errors=True)


@pytest.fixture
def postgres_db(postgres_url: str) -> str:
    """A fresh, empty database on the private server (one per test)."""
    import uuid

    import psycopg

    name = f"t_{uuid.uuid4().hex[:12]}"
    with psycopg.connect(postgres_url, autocommit=True) as con:
        con.execute(f"CREATE DATABASE {name}")
    return postgres_url.rpartition("/")[0] + f"/{name}"
