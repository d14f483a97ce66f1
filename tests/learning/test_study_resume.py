"""Studies: every trial stored at once, resumable after a kill, tagged by task and skill."""

from __future__ import annotations

import gc
import os
import signal
from pathlib import Path

import pytest
import sqlalchemy as sa

from teachfit.learning import (
    LearningError,
    ParamDomain,
    ParamSpace,
    Study,
    StudyMismatchError,
    run_study,
)
from teachfit.learning.claims import CLAIMS, release_dropped

SPACE = ParamSpace({"a": ParamDomain(-1.0, 1.0), "b": ParamDomain(0.0, 2.0)})


def rosenbrock(p: dict[str, float]) -> tuple[float, bool]:
    """Noise-free Rosenbrock in (a, b); infeasible (penalised) where a > 0.8."""
    a, b = p["a"], p["b"]
    cost = (1 - a) ** 2 + 100 * (b - a * a) ** 2
    return (cost, True) if a <= 0.8 else (500.0, False)


def open_study(path: Path, **kw: object) -> Study:
    args: dict[str, object] = dict(task="puzzle", skill="peg-in-hole", space=SPACE, method="cmaes")
    args.update(kw)
    return Study(path, seed=4, options={"popsize": 6}, **args)  # type: ignore[arg-type]


class Killer:
    """The objective of a run that is killed (KeyboardInterrupt) during its ``k``-th trial."""

    def __init__(self, k: int) -> None:
        self.k, self.calls = k, 0

    def __call__(self, p: dict[str, float]) -> tuple[float, bool]:
        self.calls += 1
        if self.calls == self.k:
            raise KeyboardInterrupt
        return rosenbrock(p)


def test_resume_after_a_kill_loses_and_repeats_nothing(tmp_path: Path) -> None:
    budget = 20
    ref = open_study(tmp_path / "ref.db")
    run_study(ref, rosenbrock, budget, workers=0)
    ref_trials = ref.trials()

    db = tmp_path / "runs" / "killed.db"
    with pytest.raises(KeyboardInterrupt):
        run_study(open_study(db), Killer(9), budget, workers=0)  # killed mid-generation
    assert len(open_study(db).trials()) == 8  # every finished trial was stored at once

    seen: list[dict[str, float]] = []

    def counting(p: dict[str, float]) -> tuple[float, bool]:
        seen.append(dict(p))
        return rosenbrock(p)

    resumed = open_study(db)
    assert resumed.n_restored == 8
    report = run_study(resumed, counting, budget, workers=0)
    assert report.restored == 8 and report.finished == 12 and not report.interrupted
    trials = resumed.trials()
    assert len(trials) == budget
    assert len({t.key for t in trials}) == budget  # none repeated
    first8 = [t.params for t in trials[:8]]
    assert all(p not in first8 for p in seen)  # finished trials were not run again
    # the killed-and-resumed study is the same study an uninterrupted run makes
    assert [t.key for t in trials] == [t.key for t in ref_trials]
    assert [t.cost for t in trials] == pytest.approx([t.cost for t in ref_trials])


def test_sigterm_stops_cleanly_and_the_run_resumes(tmp_path: Path) -> None:
    db = f"sqlite:///{tmp_path / 'term.db'}"  # any SQLAlchemy URL
    calls = []

    def terminated(p: dict[str, float]) -> tuple[float, bool]:
        calls.append(p)
        if len(calls) == 5:
            os.kill(os.getpid(), signal.SIGTERM)
        return rosenbrock(p)

    before = signal.getsignal(signal.SIGTERM)
    report = run_study(open_study(db), terminated, 30, workers=0)
    assert report.interrupted and report.finished == 5  # the running trial was finished
    assert signal.getsignal(signal.SIGTERM) is before
    report = run_study(open_study(db), rosenbrock, 30, workers=0)
    assert report.restored == 5 and report.finished == 25
    assert open_study(db).best().feasible


def test_a_study_from_another_task_or_skill_is_an_error(tmp_path: Path) -> None:
    db = tmp_path / "s.db"
    run_study(open_study(db), rosenbrock, 3, workers=0)
    with pytest.raises(StudyMismatchError, match="task"):
        open_study(db, task="key")
    with pytest.raises(StudyMismatchError, match="skill"):
        open_study(db, skill="plug-in-socket")
    with pytest.raises(StudyMismatchError, match="method"):
        Study(db, task="puzzle", skill="peg-in-hole", space=SPACE, method="pso", seed=4)
    with pytest.raises(StudyMismatchError, match="space"):
        other = ParamSpace({"a": ParamDomain(-1.0, 1.0), "b": ParamDomain(0.0, 3.0)})
        open_study(db, space=other)
    with pytest.raises(LearningError, match="already has 3 trials"):
        open_study(db, resume=False)


def test_failures_are_stored_at_the_penalty_and_gp_bo_resumes(tmp_path: Path) -> None:
    db = tmp_path / "bo.db"
    kw = dict(task="puzzle", skill="peg-in-hole", space=SPACE, method="bo", penalty=700.0)
    opts = {"n_startup": 4}  # the GP sampler (the default) after 4 random trials
    run_study(Study(db, options=opts, **kw), rosenbrock, 6, workers=0)  # type: ignore[arg-type]
    study = Study(db, options=opts, **kw)  # type: ignore[arg-type]
    run_study(study, lambda p: float("nan"), 8, workers=0)
    trials = study.trials()
    assert len(trials) == 8 and len({t.key for t in trials}) == 8
    assert [t.outcome for t in trials[6:]] == ["error", "error"]
    assert all(t.cost == 700.0 and not t.feasible for t in trials[6:])


def test_a_cell_that_needs_a_person_stops_the_run_and_charges_no_trial(tmp_path: Path) -> None:
    """A part lost from the grasp (any NeedsAPerson) ends the run at once: the trials before
    it are stored, the one it interrupted is neither stored as failed nor lost for the resume."""
    from teachfit.robot.franka.grasp import PartLost

    calls = []

    def drops_the_part(p: dict[str, float]) -> tuple[float, bool]:
        calls.append(p)
        if len(calls) == 4:
            raise PartLost("the part is no longer in the gripper")
        return rosenbrock(p)

    db = tmp_path / "lost.db"
    with pytest.raises(PartLost):
        run_study(open_study(db), drops_the_part, 10, workers=0)
    stored = open_study(db).trials()
    assert len(stored) == 3 and all(r.outcome != "error" for r in stored)
    report = run_study(open_study(db), rosenbrock, 10, workers=0)
    assert report.finished == 7 and len(open_study(db).trials()) == 10


def test_a_study_collected_in_anothers_transaction_releases_its_claims_after_it(
    tmp_path: Path,
) -> None:
    """A Study dropped without ``close()`` is finalized by the garbage collector in whatever
    thread it interrupts, here one inside a write transaction on the same SQLite file (as a
    resume in the same process can be): its claims are released after that transaction, by
    the next study made or asked. Released inside it, the release waited for its own thread
    until the busy timeout (120 s) and then failed, leaving the claim behind."""
    db = tmp_path / "gc.db"
    old = open_study(db)
    cand = old.ask(10)
    assert cand is not None
    old.cycle = old  # type: ignore[attr-defined]  # freed by the cyclic collector only
    del old
    new = open_study(db)
    held = sa.select(CLAIMS.c.key).where(CLAIMS.c.key == cand.key)
    with new._claims.engine.begin() as conn:
        gc.collect()  # the old study's finalizer runs here, inside the write transaction
        assert conn.execute(held).all() != []  # not released inside it
    release_dropped()  # as the next study made or asked does
    with new._claims.engine.connect() as conn:
        assert conn.execute(held).all() == []  # released after it
    new.close()
