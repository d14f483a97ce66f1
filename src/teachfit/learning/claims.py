"""Claims: which process runs which trial key of a study that several processes share.

Population learners (CMA-ES, PSO) hand out the same keys (``r0g5m0``) in every process that
works on one study, since each rebuilds the same learner from the same stored trials. Before a
process runs a key it *claims* it: one row per ``(study, key)`` in the table
``teachfit_claims`` of the study's own database, written in a transaction that first locks
the study's row in ``teachfit_locks`` (a row lock in PostgreSQL; SQLite serialises every
transaction with ``BEGIN IMMEDIATE``). Inside that transaction the budget is checked too:
finished keys plus keys running in live processes never exceed the requested trial count, so
processes together finish exactly that many trials.

A claim moves ``running`` -> ``storing`` (just before the trial is written to the Optuna
storage) -> ``done`` (just after). A claim whose owner is dead can be taken over:

* owner on this machine (same host name, boot id and PID namespace): dead as soon as its PID
  is gone or belongs to a newer process (start time differs);
* any owner: dead when its heartbeat (written by a thread every ``timeout / 4`` s) is older
  than ``timeout`` s -- a process on another machine, or one that dropped a study unclosed.
  Clocks of the machines must agree to well within ``timeout`` (NTP).

A dead owner's ``running`` claim never reached the storage, so it is run again; a dead
owner's ``storing`` claim is resolved by :meth:`Claims.resolve` against the stored trials.
"""

from __future__ import annotations

import atexit
import json
import os
import socket
import threading
import time
import uuid
import weakref
from collections.abc import Callable, Collection, Iterable, Sequence
from dataclasses import dataclass
from enum import Enum
from typing import TypeVar

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine
from sqlalchemy.exc import DBAPIError

_META = sa.MetaData()
CLAIMS = sa.Table(
    "teachfit_claims",
    _META,
    sa.Column("study", sa.String(512), primary_key=True),
    sa.Column("key", sa.String(128), primary_key=True),
    sa.Column("owner", sa.String(256), nullable=False),
    sa.Column("host", sa.String(256), nullable=False),
    sa.Column("pid", sa.Integer, nullable=False),
    sa.Column("pid_start", sa.BigInteger, nullable=False),
    sa.Column("state", sa.String(16), nullable=False),
    sa.Column("heartbeat", sa.Float, nullable=False),
    sa.Column("u", sa.Text, nullable=False),
)
LOCKS = sa.Table(
    "teachfit_locks",
    _META,
    sa.Column("study", sa.String(512), primary_key=True),
    sa.Column("n", sa.BigInteger, nullable=False),
)

_ENGINES: weakref.WeakSet[Engine] = weakref.WeakSet()


def _forget_engines_in_child() -> None:
    # a forked worker must not close (or use) its parent's database connections
    for engine in list(_ENGINES):
        engine.dispose(close=False)


os.register_at_fork(after_in_child=_forget_engines_in_child)


def serialise_sqlite(engine: Engine) -> Engine:
    """Make every transaction of an SQLite ``engine`` ``BEGIN IMMEDIATE``: concurrent
    processes then wait for each other (busy timeout) instead of failing on a lock upgrade.
    Its connections must be made with ``isolation_level=None`` (see :func:`engine_kwargs`)."""
    if engine.dialect.name == "sqlite":
        sa.event.listen(engine, "begin", lambda conn: conn.exec_driver_sql("BEGIN IMMEDIATE"))
    _ENGINES.add(engine)
    return engine


def engine_kwargs(url: str) -> dict[str, object]:
    """SQLAlchemy engine options for a shared study database at ``url``."""
    if url.startswith("sqlite"):
        return {"connect_args": {"timeout": 120.0, "isolation_level": None}}
    return {"pool_pre_ping": True}


# ------------------------------------------------------------------------------ liveness
def _boot_id() -> str:
    try:
        with open("/proc/sys/kernel/random/boot_id") as fh:
            return fh.read().strip()
    except OSError:
        return "-"


def _pid_ns() -> str:
    try:
        return str(os.stat("/proc/self/ns/pid").st_ino)
    except OSError:
        return "-"


#: this machine (and PID namespace): PIDs of owners with the same HOST can be checked here
HOST = f"{socket.gethostname()}/{_boot_id()}/{_pid_ns()}"


def pid_start(pid: int) -> int:
    """Start time of process ``pid`` (clock ticks since boot; 0 if unknown, -1 if none)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            stat = fh.read()
    except FileNotFoundError:
        return -1
    except OSError:
        return 0
    return int(stat.rpartition(")")[2].split()[19])


def pid_alive(pid: int, start: int) -> bool:
    """Whether process ``pid`` that started at ``start`` (:func:`pid_start`) still runs."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # another user's process: it exists
    now = pid_start(pid)
    if now == -1:
        return False
    if now and start and now != start:
        return False  # the PID was reused by a newer process
    try:
        with open(f"/proc/{pid}/stat") as fh:
            if fh.read().rpartition(")")[2].split()[0] == "Z":
                return False  # a zombie: dead, not yet reaped
    except OSError:
        pass
    return True


@dataclass(frozen=True)
class Claim:
    """One row of ``teachfit_claims``."""

    key: str
    owner: str
    host: str
    pid: int
    pid_start: int
    state: str
    heartbeat: float
    u: tuple[float, ...]

    def alive(self, timeout: float, now: float | None = None) -> bool:
        """Whether the owner may still finish it (see the module docstring)."""
        now = time.time() if now is None else now
        if now - self.heartbeat > timeout:
            return False
        return self.host != HOST or pid_alive(self.pid, self.pid_start)


class Verdict(Enum):
    """Answer of :meth:`Claims.claim`."""

    MINE = "mine"  # claimed (fresh, or taken over from a dead owner): run it
    ELSEWHERE = "elsewhere"  # a live process runs it
    FINISHED = "finished"  # stored already (or being stored)
    BUDGET = "budget"  # the budget is taken by finished and running keys


_T = TypeVar("_T")


def _retry(fn: Callable[[], _T], attempts: int = 8) -> _T | None:
    """Run ``fn()``, retrying a few times on database errors (races creating tables)."""
    for i in range(attempts):
        try:
            return fn()
        except DBAPIError:
            if i == attempts - 1:
                raise
            time.sleep(0.05 * 2**i)
    return None


class Claims:
    """The claims of one study, held by one owner (this process and object)."""

    def __init__(self, url: str, study: str, timeout: float = 60.0) -> None:
        if not timeout > 0:
            raise ValueError(f"claim timeout must be > 0 s, got {timeout}")
        self.study = study
        self.timeout = float(timeout)
        self.pid = os.getpid()
        self.pid_start = max(pid_start(self.pid), 0)
        self.owner = f"{HOST}/{self.pid}/{uuid.uuid4().hex[:12]}"
        self.engine = serialise_sqlite(sa.create_engine(url, **engine_kwargs(url)))
        _retry(lambda: _META.create_all(self.engine))
        _retry(self._ensure_lock_row)
        self._stop = threading.Event()
        self._beat: threading.Thread | None = None

    def _ensure_lock_row(self) -> None:
        with self.engine.begin() as conn:
            found = conn.execute(sa.select(LOCKS.c.n).where(LOCKS.c.study == self.study)).first()
            if found is None:
                conn.execute(sa.insert(LOCKS).values(study=self.study, n=0))

    # -------------------------------------------------------------------------- reading
    def _rows(self, conn: Connection) -> list[Claim]:
        rows = conn.execute(sa.select(CLAIMS).where(CLAIMS.c.study == self.study)).all()
        return [
            Claim(
                r.key,
                r.owner,
                r.host,
                r.pid,
                r.pid_start,
                r.state,
                r.heartbeat,
                tuple(json.loads(r.u)),
            )
            for r in rows
        ]

    def all(self) -> list[Claim]:
        """Every claim of the study."""
        with self.engine.begin() as conn:
            return self._rows(conn)

    # -------------------------------------------------------------------------- claiming
    def claim(
        self,
        key: str,
        u: Sequence[float],
        budget: int | None = None,
        stored: Collection[str] = (),
    ) -> tuple[Verdict, Claim | None]:
        """Claim ``key`` (point ``u``) unless finished, live elsewhere or over ``budget``.

        ``budget`` counts the keys in ``stored`` (finished trials seen in the storage, which
        may predate claims), finished claims and claims running in live processes. Returns
        the verdict and, for ``MINE`` taken over from a dead owner, the dead claim.
        """
        now = time.time()
        with self.engine.begin() as conn:
            # the lock: concurrent claimers of this study wait here until this one commits
            lock = sa.update(LOCKS).where(LOCKS.c.study == self.study)
            conn.execute(lock.values(n=LOCKS.c.n + 1))
            rows = self._rows(conn)
            mine = next((c for c in rows if c.key == key), None)
            if mine is not None and mine.state != "running":
                return Verdict.FINISHED, None
            if mine is not None and mine.owner == self.owner:
                return Verdict.MINE, None
            if mine is not None and mine.alive(self.timeout, now):
                return Verdict.ELSEWHERE, None
            taken = set(stored) | {
                c.key for c in rows if c.state != "running" or c.alive(self.timeout, now)
            }
            if budget is not None and len(taken) >= budget:
                return Verdict.BUDGET, None
            values = dict(
                owner=self.owner,
                host=HOST,
                pid=self.pid,
                pid_start=self.pid_start,
                state="running",
                heartbeat=now,
                u=json.dumps([float(x) for x in u]),
            )
            if mine is None:
                conn.execute(sa.insert(CLAIMS).values(study=self.study, key=key, **values))
            else:
                conn.execute(self._where(key, mine.owner, "running").values(**values))
        self._start_heartbeat()
        return Verdict.MINE, mine

    def _where(self, key: str, owner: str, state: str) -> sa.Update:
        return sa.update(CLAIMS).where(
            CLAIMS.c.study == self.study,
            CLAIMS.c.key == key,
            CLAIMS.c.owner == owner,
            CLAIMS.c.state == state,
        )

    def begin_store(self, key: str) -> bool:
        """``running`` -> ``storing`` if this owner still holds ``key`` (False: it lost the
        claim to another process after missing heartbeats; its result must be dropped)."""
        with self.engine.begin() as conn:
            res = conn.execute(self._where(key, self.owner, "running").values(state="storing"))
            return res.rowcount == 1

    def end_store(self, key: str) -> None:
        """``storing`` -> ``done``: the trial is in the storage."""
        with self.engine.begin() as conn:
            conn.execute(self._where(key, self.owner, "storing").values(state="done"))

    def release(self, keys: Iterable[str] | None = None) -> int:
        """Give up this owner's running claims (all, or ``keys``): others may run them now."""
        stmt = sa.delete(CLAIMS).where(
            CLAIMS.c.study == self.study, CLAIMS.c.owner == self.owner, CLAIMS.c.state == "running"
        )
        if keys is not None:
            stmt = stmt.where(CLAIMS.c.key.in_(list(keys)))
        with self.engine.begin() as conn:
            return int(conn.execute(stmt).rowcount)

    def resolve(self, dead_storing: Iterable[Claim], stored: set[str]) -> None:
        """Settle ``storing`` claims of dead owners: ``done`` if the key is in ``stored``
        (read *after* the owners were seen dead), else back to ``running`` (to be re-run)."""
        with self.engine.begin() as conn:
            for c in dead_storing:
                state = "done" if c.key in stored else "running"
                conn.execute(self._where(c.key, c.owner, "storing").values(state=state))

    # -------------------------------------------------------------------------- heartbeat
    def beat(self) -> None:
        """Refresh the heartbeat of this owner's unfinished claims."""
        with self.engine.begin() as conn:
            conn.execute(
                sa.update(CLAIMS)
                .where(
                    CLAIMS.c.study == self.study,
                    CLAIMS.c.owner == self.owner,
                    CLAIMS.c.state != "done",
                )
                .values(heartbeat=time.time())
            )

    def _start_heartbeat(self) -> None:
        if self._beat is not None and self._beat.is_alive():
            return
        if os.getpid() != self.pid:
            return  # a forked copy holds no claims of its own

        def loop(stop: threading.Event, claims: weakref.ref[Claims], period: float) -> None:
            while not stop.wait(period):
                owner = claims()
                if owner is None:
                    return
                try:
                    owner.beat()
                except Exception:  # the next beat tries again; a missed one is harmless
                    pass
                del owner

        self._beat = threading.Thread(
            target=loop,
            args=(self._stop, weakref.ref(self), self.timeout / 4),
            name="teachfit-claims-heartbeat",
            daemon=True,
        )
        self._beat.start()

    def drop(self) -> None:
        """For a finalizer (a study dropped unclosed): stop the heartbeat now and release the
        claims at the next :func:`release_dropped`. The garbage collector runs finalizers in
        whichever thread it interrupts, maybe one inside a write transaction on the same
        SQLite file: a release there would wait for that very thread, up to the busy timeout
        (120 s), then fail and leave the claims behind."""
        self._stop.set()
        _DROPPED.append(self)

    def close(self) -> None:
        """Stop the heartbeat and release unfinished running claims (best effort: claims
        left behind die with this process anyway)."""
        self._stop.set()
        if os.getpid() != self.pid:
            return
        try:
            self.release()
        except DBAPIError:
            pass  # the database is gone (e.g. a server stopped first)
        finally:
            self.engine.dispose()


#: claims of studies dropped unclosed (:meth:`Claims.drop`), to release where it is safe
_DROPPED: list[Claims] = []


def release_dropped() -> None:
    """Release the claims of studies dropped unclosed (:meth:`Claims.drop`). Called where this
    thread holds no transaction: a study's creation and each ``ask``, and at exit."""
    while _DROPPED:
        _DROPPED.pop().close()


# at exit after the finalizers, which register later (atexit runs last in, first out)
atexit.register(release_dropped)
