"""A shared study survives a SIGKILL at every point of the claim protocol, on SQLite and on
PostgreSQL: of a pool worker (the study goes on in the same process) and of a whole process
(another one takes its keys over). Points: before a claim, after it, mid-trial, while storing
(claim ``storing``, trial not stored), stored (trial stored, claim not yet ``done``), done.

Each run forks two processes from this one (no second import): a *holder* claims the first key
of a CMA-ES generation and holds it (its trial waits at a gate), then a *victim* runs the rest
of the generation with hooks (patched into the victim alone) that SIGKILL it, or one of its
pool workers, at the chosen points. The gate opens once the victim has died (or all its kills
were made); the holder, and a victim that survives, must then finish the study: exactly the
trials asked for, each key once, the very trials a single uninterrupted process makes, every
claim ``done`` -- and no process left waiting: one still running after ``WEDGED_S`` (a healthy
run takes about a second) is killed and fails the test as wedged.
"""

from __future__ import annotations

import functools
import multiprocessing
import os
import signal
import time
from collections import Counter
from collections.abc import Callable, Collection, Sequence
from pathlib import Path

import pytest
import sqlalchemy as sa

from teachfit.learning import Study, run_study, runner
from teachfit.learning.claims import CLAIMS, Claim, Claims, Verdict, pid_alive

from .share_worker import SPACE, cost

POINTS = ("claim", "claimed", "trial", "storing", "stored", "done")
POPSIZE = 8  # the holder takes key 1 of generation 1; the victim has keys 2 to 8
BUDGET = POPSIZE + 2  # and 2 keys of generation 2: the first 2, asked in order by both
WEDGED_S = 120.0  # a process still running after this long is wedged (a healthy one: ~1 s)
FORK = multiprocessing.get_context("fork")

#: kills to make: (point, n) -- at the n-th passage of the victim through the point
Plan = list[tuple[str, int]]


def _open(url: str, name: str = "teachfit") -> Study:
    return Study(
        url,
        name=name,
        task="puzzle",
        skill="peg-in-hole",
        space=SPACE,
        method="cmaes",
        seed=7,
        options={"popsize": POPSIZE},
        penalty=500.0,
    )


@pytest.fixture(scope="module")
def expected(tmp_path_factory: pytest.TempPathFactory) -> list[tuple[str, float]]:
    """(key, cost) of the trials one uninterrupted process makes."""
    ref = _open(f"sqlite:///{tmp_path_factory.mktemp('ref') / 'ref.db'}")
    run_study(ref, cost, BUDGET, workers=0)
    out = sorted((t.key, t.cost) for t in ref.trials())
    ref.close()
    return out


@pytest.fixture(params=["sqlite", "postgresql"])
def new_study(request: pytest.FixtureRequest, tmp_path: Path) -> Callable[[int], tuple[str, str]]:
    """``new_study(i)``: (URL, study name) of an empty study: a new SQLite file, or a new name
    in one database of the private PostgreSQL server."""
    if request.param == "sqlite":
        return lambda i: (f"sqlite:///{tmp_path / f'shared{i}.db'}", "teachfit")
    url = str(request.getfixturevalue("postgres_db"))
    return lambda i: (url, f"study{i}")


def _note(path: Path, line: str) -> None:
    with path.open("a") as fh:
        fh.write(line + "\n")


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines() if path.exists() else []


def _objective(fire: Path, who: str, p: dict[str, float]) -> tuple[float, bool]:
    """The cost, run in a pool worker; the first trial to find ``fire`` takes it and SIGKILLs
    its worker (``who="worker"``) or the worker's parent, the victim (then itself)."""
    try:
        fire.unlink()
    except FileNotFoundError:
        return cost(p)
    _note(fire.with_suffix(".fired"), "trial")
    if who == "main":
        os.kill(os.getppid(), signal.SIGKILL)
    os.kill(os.getpid(), signal.SIGKILL)
    raise AssertionError("unreachable")


class Killer:
    """SIGKILLs this process (``who="main"``) or its pool worker at the n-th passage of each
    ``(point, n)`` of ``plan``, noting each kill in ``fired`` first (main) or after it."""

    def __init__(self, who: str, plan: Plan, fired: Path) -> None:
        self.who, self.plan, self.fired = who, set(plan), fired
        self.seen: Counter[str] = Counter()

    def passed(self, point: str) -> None:
        self.seen[point] += 1
        if (point, self.seen[point]) not in self.plan:
            return
        if point == "trial":  # the next trial to start fires (see _objective)
            self.fired.with_suffix(".fire").touch()
        elif self.who == "main":
            _note(self.fired, point)
            os.kill(os.getpid(), signal.SIGKILL)
        else:
            pids = [w.pid for w in multiprocessing.active_children() if w.pid]
            for pid in pids:
                os.kill(pid, signal.SIGKILL)
            while any(pid_alive(pid, 0) for pid in pids):
                time.sleep(0.01)
            time.sleep(0.2)  # the pool sees it die: the next submit finds it broken
            _note(self.fired, point if pids else f"{point} (no worker to kill)")

    def install(self, patch: pytest.MonkeyPatch) -> None:
        """Hook the claim protocol of this (forked) process."""
        claim, begin, end = Claims.claim, Claims.begin_store, Claims.end_store

        def claim_hook(
            c: Claims,
            key: str,
            u: Sequence[float],
            budget: int | None = None,
            stored: Collection[str] = (),
        ) -> tuple[Verdict, Claim | None]:
            self.passed("claim")
            out = claim(c, key, u, budget, stored)
            if out[0] is Verdict.MINE:
                self.passed("claimed")
                self.passed("trial")  # the trial of this claim is the next one to start
            return out

        def begin_hook(c: Claims, key: str) -> bool:
            ok = begin(c, key)
            self.passed("storing")
            return ok

        def end_hook(c: Claims, key: str) -> None:
            self.passed("stored")
            end(c, key)
            self.passed("done")

        patch.setattr(Claims, "claim", claim_hook)
        patch.setattr(Claims, "begin_store", begin_hook)
        patch.setattr(Claims, "end_store", end_hook)


def _quick_polls() -> pytest.MonkeyPatch:
    """In a forked process: look at the study every 0.05 s while others run its trials."""
    patch = pytest.MonkeyPatch()
    patch.setattr(runner, "POLL_S", 0.05)
    return patch


def _holder(url: str, name: str, gate: Path) -> None:
    """Claim the first key and hold it until ``gate`` exists, then finish the study."""
    _quick_polls()

    def objective(p: dict[str, float]) -> tuple[float, bool]:
        held = gate.with_suffix(".held")
        if not held.exists():
            held.touch()
            while not gate.exists():
                time.sleep(0.01)
        return cost(p)

    study = _open(url, name)
    run_study(study, objective, BUDGET, workers=0, handle_signals=False)
    study.close()


def _victim(url: str, name: str, who: str, plan: Plan, fired: Path, workers: int) -> None:
    Killer(who, plan, fired).install(_quick_polls())
    study = _open(url, name)
    objective = functools.partial(_objective, fired.with_suffix(".fire"), who)
    run_study(study, objective, BUDGET, workers=workers, handle_signals=False)
    study.close()


def _until(what: str, cond: Callable[[], bool], procs: list[multiprocessing.Process]) -> None:
    deadline = time.monotonic() + WEDGED_S
    while not cond():
        if time.monotonic() > deadline:
            pytest.fail(f"{what} did not happen within {WEDGED_S} s: wedged")
        if any(p.exitcode not in (None, 0) for p in procs):
            break  # a victim killed itself; the caller checks what it noted
        time.sleep(0.01)


def _kill_run(study: tuple[str, str], tmp: Path, who: str, plan: Plan, workers: int) -> list[str]:
    """One holder and one victim with ``plan``; returns the kills the victim noted."""
    tmp.mkdir()
    gate, fired = tmp / "gate", tmp / "kills.fired"
    holder = FORK.Process(target=_holder, args=(*study, gate))
    holder.start()
    procs = [holder]
    try:
        _until("the holder's first claim", gate.with_suffix(".held").exists, procs)
        victim = FORK.Process(target=_victim, args=(*study, who, plan, fired, workers))
        victim.start()
        procs.append(victim)
        _until("the victim's kills", lambda: len(_lines(fired)) >= len(plan), procs)
        gate.touch()
        for p in procs:
            p.join(WEDGED_S)
    finally:
        for p in procs:
            if p.is_alive():
                p.kill()
                p.join()
    assert holder.exitcode == 0, f"the holder wedged or failed: exit {holder.exitcode}"
    want = -signal.SIGKILL if who == "main" else 0
    assert victim.exitcode == want, f"the victim wedged or failed: exit {victim.exitcode}"
    return _lines(fired)


def _check(study: tuple[str, str], expected: list[tuple[str, float]]) -> int:
    """The study holds the very trials one process makes, each once; every claim is done.
    Returns how many it holds."""
    url, name = study
    final = _open(url, name)
    trials = final.trials()
    engine = sa.create_engine(url)
    with engine.connect() as conn:
        q = sa.select(CLAIMS.c.state).where(CLAIMS.c.study == name)
        states = Counter(r.state for r in conn.execute(q))
    engine.dispose()
    final.close()
    keys = [t.key for t in trials]
    assert sorted((t.key, t.cost) for t in trials) == expected
    assert len(keys) == len(set(keys)) == BUDGET and states == {"done": BUDGET}
    return len(trials)


#: where a worker of the victim (one worker) is killed, each point once per run, in three orders;
#: ("claim", n): before the n-th claim asked (the 1st, of the holder's key, is refused), others:
#: at the victim's n-th key of its own. Each kill finds a worker, the pool replaced after each
WORKER_PLANS = [
    [("claim", 3), ("trial", 3), ("claimed", 4), ("storing", 4), ("stored", 5), ("done", 6)],
    [("done", 1), ("stored", 2), ("storing", 3), ("trial", 4), ("claimed", 5), ("claim", 7)],
    [("trial", 1), ("stored", 1), ("claim", 4), ("done", 3), ("claimed", 5), ("storing", 6)],
]
#: where a whole victim process (two workers) is killed, one run each
MAIN_POINTS = [
    ("claim", 5),
    ("claimed", 2),
    ("trial", 3),
    ("storing", 2),
    ("stored", 4),
    ("done", 3),
]


def _kill_runs(
    new_study: Callable[[int], tuple[str, str]],
    tmp: Path,
    expected: list[tuple[str, float]],
    who: str,
    plans: list[Plan],
    workers: int,
) -> None:
    """A run per plan, each in a new study; every kill of each plan made, each study whole."""
    stored = []
    for i, plan in enumerate(plans):
        study = new_study(i)
        fired = _kill_run(study, tmp / f"run{i}", who, plan, workers)
        assert sorted(fired) == sorted(point for point, _ in plan)  # a worker each, if who=worker
        stored.append(_check(study, expected))
    storage = study[0].partition(":")[0]
    kills = sum(map(len, plans))
    print(
        f"\n{storage}: {kills} kills of a {who} in {len(plans)} studies: requested {BUDGET} each, "
        f"stored {stored}, 0 duplicates, 0 wedged"
    )


def test_a_worker_killed_at_every_point_is_replaced_and_its_trial_run(
    new_study: Callable[[int], tuple[str, str]],
    tmp_path: Path,
    expected: list[tuple[str, float]],
) -> None:
    _kill_runs(new_study, tmp_path, expected, "worker", WORKER_PLANS, workers=1)


def test_a_process_killed_at_every_point_has_its_keys_taken_over(
    new_study: Callable[[int], tuple[str, str]],
    tmp_path: Path,
    expected: list[tuple[str, float]],
) -> None:
    _kill_runs(new_study, tmp_path, expected, "main", [[pn] for pn in MAIN_POINTS], workers=2)
