"""Opening a learning run: a stored study resumes only with the same settings; the policies."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from teachfit.core.params import LearningError
from teachfit.learning.launch import LearnRequest, method_options, open_learning, run_learning
from teachfit.learning.study import StudyMismatchError


def _request(db: Path, **changes: object) -> LearnRequest:
    req = LearnRequest("puzzle", "peg-in-hole", "cmaes", 2, str(db), workers=0, starts=1)
    return dataclasses.replace(req, **changes)


def test_a_stored_study_resumes_only_with_the_same_settings(tmp_path: Path) -> None:
    db = tmp_path / "p.db"
    report = run_learning(open_learning(_request(db)))
    assert report.finished == 2
    with pytest.raises(LearningError, match="already has 2 trials.*resume"):
        open_learning(_request(db, trials=3))
    launch = open_learning(_request(db, trials=3, resume=True))
    assert launch.study.n_restored == 2
    run_learning(launch)
    assert launch.study.n_finished == 3
    with pytest.raises(StudyMismatchError, match="task: stored 'puzzle', asked 'key'"):
        open_learning(_request(db, task="key", resume=True))
    with pytest.raises(StudyMismatchError, match="differs.*space"):
        open_learning(_request(db, controller="impedance", resume=True))
    with pytest.raises(StudyMismatchError, match="seed"):
        open_learning(_request(db, seed=3, resume=True))


def test_a_stored_latin_hypercube_keeps_its_size_and_cannot_grow(tmp_path: Path) -> None:
    db = tmp_path / "l.db"
    launch = open_learning(_request(db, method="lhs", trials=2))
    assert launch.options == method_options("lhs", 2) == {"n": 2}
    run_learning(launch)
    with pytest.raises(LearningError, match="Latin hypercube has 2 points"):
        open_learning(_request(db, method="lhs", trials=3, resume=True))
    assert open_learning(_request(db, method="lhs", trials=2, resume=True)).options == {"n": 2}


def test_bad_requests_are_refused_before_a_study_is_written(tmp_path: Path) -> None:
    db = tmp_path / "x.db"
    for changes, message in (
        ({"method": "sgd"}, "unknown learning method"),
        ({"trials": 0}, "--trials must be >= 1"),
        ({"study": "nosuch://x"}, "unknown database scheme"),
        ({"ray": "local", "workers": 0}, "--workers 0"),
    ):
        with pytest.raises(LearningError, match=message):
            open_learning(_request(db, **changes))
    assert not db.exists()


def test_bo_starts_with_a_quarter_of_its_trials_at_random() -> None:
    assert method_options("bo", 40) == {"n_startup": 10}
    assert method_options("bo", 4) == {"n_startup": 2}
    assert method_options("cmaes", 40) == {}
