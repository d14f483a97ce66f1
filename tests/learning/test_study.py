"""A study shared by several processes: each key runs once, a dead process's keys are re-run,
and together they finish exactly the budget -- on SQLite and on a real PostgreSQL server."""

from __future__ import annotations

import json
import multiprocessing
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from multiprocessing.process import BaseProcess
from pathlib import Path

import pytest
import sqlalchemy as sa

from teachfit.learning import Study, TrialResult, run_study
from teachfit.learning.claims import CLAIMS, HOST, Claims, Verdict

from .share_worker import SPACE, cost, open_shared

FORK = multiprocessing.get_context("fork")


@pytest.fixture(params=["sqlite", "postgresql"])
def shared_url(request: pytest.FixtureRequest, tmp_path: Path) -> str:
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'shared.db'}"
    return str(request.getfixturevalue("postgres_db"))


def _running_claims(url: str, pid: int) -> list[str]:
    engine = sa.create_engine(url)
    try:
        with engine.connect() as conn:
            q = sa.select(CLAIMS.c.key).where(CLAIMS.c.pid == pid, CLAIMS.c.state == "running")
            return [r.key for r in conn.execute(q)]
    except sa.exc.DBAPIError:  # tables not created yet
        return []
    finally:
        engine.dispose()


def _claim_pids(url: str) -> set[int]:
    engine = sa.create_engine(url)
    try:
        with engine.connect() as conn:
            return {r.pid for r in conn.execute(sa.select(CLAIMS.c.pid))}
    except sa.exc.DBAPIError:
        return set()
    finally:
        engine.dispose()


def _share(url: str, budget: int, sleep_s: float, out: Path, mark: Path | None) -> None:
    """A process of the shared study (forked from the test's: no second import): runs it to
    ``budget`` and writes how many trials it finished to ``out``."""

    def objective(p: dict[str, float]) -> tuple[float, bool]:
        if mark is not None:
            with mark.open("a") as fh:
                fh.write("trial\n")
        return cost(p, sleep_s)

    rep = run_study(open_shared(url, "cmaes"), objective, budget, workers=0)
    out.write_text(f"finished={rep.finished} restored={rep.restored}")


def test_four_processes_share_one_study_and_one_is_killed(shared_url: str, tmp_path: Path) -> None:
    budget = 16  # 4 whole CMA-ES generations of 4
    ref = open_shared(f"sqlite:///{tmp_path / 'ref.db'}", "cmaes")
    run_study(ref, cost, budget, workers=0)
    expected = sorted((t.key, t.cost) for t in ref.trials())
    mark = tmp_path / "victim.marks"

    def begun() -> int:
        return len(mark.read_text().splitlines()) if mark.exists() else 0

    def start(i: int, sleep_s: float, marks: Path | None = None) -> BaseProcess:
        args = (shared_url, budget, sleep_s, tmp_path / f"out{i}", marks)
        proc = FORK.Process(target=_share, args=args)
        proc.start()
        return proc

    def wait_for(what: str, cond: Callable[[], bool], timeout: float = 180.0) -> None:
        deadline = time.monotonic() + timeout
        while not cond():
            if time.monotonic() > deadline or not victim.is_alive():
                victim.kill()
                pytest.fail(f"{what} did not happen: the victim exited {victim.exitcode}")
            time.sleep(0.05)

    # the victim's trials never end by themselves (600 s), so it is killed in its first one
    # whatever the machine's load: no race between its next claim and the others' trials
    victim = start(0, 600.0, mark)
    procs = [victim]
    try:
        wait_for("a first trial of the victim", lambda: begun() > 0)
        procs += [start(i, 0.05) for i in (1, 2, 3)]
        others = {p.pid for p in procs[1:]}
        wait_for("a claim of the others", lambda: bool(_claim_pids(shared_url) & others))
        # what it holds as it dies (read before the kill: a survivor on this host takes a dead
        # owner's claim over at once, so afterwards the claim may already be another's)
        held = _running_claims(shared_url, victim.pid)  # type: ignore[arg-type]
        victim.kill()
        victim.join(10)
        for p in procs[1:]:
            p.join(300)
    finally:
        for p in procs:
            if p.is_alive():
                p.kill()
                p.join()
    assert victim.exitcode == -signal.SIGKILL
    assert all(p.exitcode == 0 for p in procs[1:]), [p.exitcode for p in procs]
    outs = [(tmp_path / f"out{i}").read_text() for i in (1, 2, 3)]

    final = open_shared(shared_url, "cmaes")
    trials = final.trials()
    keys = [t.key for t in trials]
    duplicates = len(keys) - len(set(keys))
    lost = len({k for k, _ in expected} - set(keys))
    engine = sa.create_engine(final.url)
    with engine.connect() as conn:
        rows = conn.execute(sa.select(CLAIMS.c.key, CLAIMS.c.pid, CLAIMS.c.state)).all()
    engine.dispose()
    print(
        f"\n{shared_url.partition(':')[0]}: 4 processes (1 SIGKILLed holding {held}), "
        f"requested {budget}, stored {len(trials)}, duplicates {duplicates}, lost {lost}, "
        f"claims left running {sum(r.state != 'done' for r in rows)}"
    )
    assert len(trials) == budget and duplicates == 0 and lost == 0
    # the very trials (keys, costs) a single uninterrupted process makes
    assert sorted((t.key, t.cost) for t in trials) == expected
    assert {r.state for r in rows} == {"done"} and len(rows) == budget
    # the key the killed process was running was run again by another process
    assert held and all(r.pid != victim.pid for r in rows if r.key in held)
    by_victim = sum(r.pid == victim.pid for r in rows)
    assert sum(int(o.split("finished=")[1].split()[0]) for o in outs) + by_victim == budget
    final.close()
    ref.close()


def test_two_studies_in_one_process_share_out_a_generation(tmp_path: Path) -> None:
    url = f"sqlite:///{tmp_path / 'two.db'}"
    a, b = open_shared(url, "cmaes"), open_shared(url, "cmaes")
    got_a = [a.ask(8), a.ask(8)]
    got_b = [b.ask(8), b.ask(8), b.ask(8)]
    assert [c.key for c in got_a] == ["r0g0m0", "r0g0m1"]  # type: ignore[union-attr]
    assert [c.key if c else None for c in got_b] == ["r0g0m2", "r0g0m3", None]  # waits for a
    for c in got_b[:2]:
        assert c is not None and b.tell(c, TrialResult(*cost(b.params_of(c)))) is not None
    assert a.ask(8) is None  # a's learner waits for its own two
    for c in got_a:
        assert c is not None and a.tell(c, TrialResult(*cost(a.params_of(c)))) is not None
    nxt = b.ask(8)  # b adopts a's two trials: the generation is complete, the next begins
    assert nxt is not None and nxt.key == "r0g1m0"
    assert b.n_finished == 4 and a.n_finished == 4


def test_bo_and_lhs_processes_never_run_a_key_twice(tmp_path: Path) -> None:
    for method, opts in (("bo", {"sampler": "tpe", "n_startup": 2}), ("lhs", {"n": 6})):
        url = f"sqlite:///{tmp_path / f'{method}.db'}"
        kw = dict(task="puzzle", skill="peg-in-hole", space=SPACE, method=method, seed=3)
        a = Study(url, options=opts, **kw)  # type: ignore[arg-type]
        b = Study(url, options=opts, **kw)  # type: ignore[arg-type]
        for _ in range(3):  # same seed, same first points: b gets other keys, never a's
            for s in (a, b):
                c = s.ask(6)
                if c is not None:
                    s.tell(c, None)
        assert a.ask(6) is None and a.settled(6) and b.settled(6)
        keys = [t.key for t in a.trials()]
        assert len(keys) == 6 and len(set(keys)) == 6, (method, keys)


def test_claims_of_dead_or_silent_processes_are_taken_over(tmp_path: Path) -> None:
    url = f"sqlite:///{tmp_path / 'dead.db'}"
    study = open_shared(url, "lhs")
    gone = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        text=True,
        capture_output=True,
        check=True,
    )
    pid = int(gone.stdout)  # a process of this machine that has exited
    with study._claims.engine.begin() as conn:
        for key, state in (("i0", "running"), ("i1", "storing")):  # killed running / storing
            row = dict(owner=f"{HOST}/{pid}/x", host=HOST, pid=pid, pid_start=1, state=state)
            u = json.dumps(list(study.learner.design[int(key[1:])]))  # type: ignore[attr-defined]
            conn.execute(
                sa.insert(CLAIMS).values(
                    study="teachfit", key=key, heartbeat=time.time(), u=u, **row
                )
            )
    first = study.ask(40)
    assert first is not None and first.key == "i0"  # taken over at once: its PID is gone
    nxt = study.ask(40)  # i1 looks stored-to-be; the next free key is i2
    assert nxt is not None and nxt.key == "i2"
    study.sync()  # i1 is not in the storage: its claim is settled back to running, and taken
    again = study.ask(40)
    assert again is not None and again.key == "i1"
    # a live process (here: another owner in this one) keeps its claim ...
    other = Claims(study.url, "teachfit", timeout=60.0)
    assert other.claim("i3", [0.5, 0.5])[0] is Verdict.MINE
    assert study._claims.claim("i3", [0.5, 0.5])[0] is Verdict.ELSEWHERE
    # ... until its heartbeat is older than the (here: short) timeout
    impatient = Claims(study.url, "teachfit", timeout=0.3)
    time.sleep(0.4)
    verdict, taken = impatient.claim("i3", [0.5, 0.5])
    assert verdict is Verdict.MINE and taken is not None and taken.owner == other.owner
    assert not other.begin_store("i3")  # the silent owner lost it: it must not store it
    other.close()
    impatient.close()


def test_a_study_file_that_is_no_database_is_one_clear_error(tmp_path: Path) -> None:
    import sqlite3

    from teachfit.core.params import LearningError
    from teachfit.learning.study import storage_url, stored_tags

    junk = tmp_path / "junk.db"
    junk.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(LearningError, match="junk.db is not an SQLite database"):
        storage_url(junk)
    good = tmp_path / "good.db"
    with sqlite3.connect(good) as con:
        con.execute("create table t (x)")
    cut = tmp_path / "cut.db"
    cut.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    with pytest.raises(LearningError, match="cut.db: database disk image is malformed"):
        stored_tags(cut)
    with pytest.raises(LearningError, match="is a folder"):
        storage_url(tmp_path)


def test_an_sqlite_study_reads_only_new_trials_and_all_after_a_foreign_one(
    tmp_path: Path,
) -> None:
    """Two openers of one SQLite study: each sync sees what the other stored (read above the
    last trial id seen), and a trial some other writer left unfinished makes it read all."""
    import optuna

    url = f"sqlite:///{tmp_path / 's.db'}"
    a, b = open_shared(url, "lhs"), open_shared(url, "lhs")

    def store(study: Study) -> None:
        cand = study.ask(8)
        assert cand is not None
        study.tell(cand, TrialResult(*cost(study.params_of(cand))))

    for n in (1, 2, 3):
        store(a)
        b.sync()
        assert b.n_finished == n and len(b.trials()) == n
    assert b._read_above is not None  # incremental
    raw = optuna.load_study(study_name="teachfit", storage=url)
    raw.ask()  # a RUNNING trial: it may finish later under a lower id than new ones
    store(a)
    b.sync()
    assert b._read_above is None and b.n_finished == 4  # fell back to full reads
    store(a)
    b.sync()
    assert b.n_finished == 5 and [t.key for t in b.trials()] == [t.key for t in a.trials()]
    a.close()
    b.close()
