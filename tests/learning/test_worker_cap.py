"""Worker counts are capped: never more worker processes than trials left, nor more than
``WORKERS_PER_CPU`` per core; a cut request says so in one line."""

from __future__ import annotations

import logging
import multiprocessing
import os
from pathlib import Path

import pytest

from teachfit.learning import ParamDomain, ParamSpace, Study, TrialResult, run_study
from teachfit.learning.runner import WORKERS_PER_CPU, cap_workers

SPACE = ParamSpace({"a": ParamDomain(0.0, 1.0)})


def pid_cost(p: dict[str, float]) -> TrialResult:
    """A cost that records the worker process it ran in."""
    return TrialResult((p["a"] - 0.5) ** 2, info={"pid": float(os.getpid())})


def test_cap_workers_by_trials_left_and_cores() -> None:
    n, note = cap_workers(1000, 4, cpus=2)
    assert n == 4 and note.startswith("1000 workers asked: using 4 (4 trial(s) left, 2 core(s)")
    n, note = cap_workers(1000, 500, cpus=2)
    assert n == 2 * WORKERS_PER_CPU and f"using {n}" in note
    assert cap_workers(3, 10, cpus=2) == (3, "")  # within both limits: as asked, silently
    assert cap_workers(None, 10, cpus=6) == (6, "")  # the default: one per core
    assert cap_workers(None, 2, cpus=6) == (2, "")  # ... but no more than trials left
    assert cap_workers(5, 0, cpus=2) == (1, "")  # nothing to run: the pool starts none


def test_a_thousand_workers_for_four_trials_fork_four(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    study = Study(
        tmp_path / "cap.db",
        task="puzzle",
        skill="peg-in-hole",
        space=SPACE,
        method="lhs",
        seed=1,
        options={"n": 4},
    )
    alive: list[int] = []  # worker processes of this one, as each trial is stored

    def count(rec: object) -> None:
        alive.append(len(multiprocessing.active_children()))

    with caplog.at_level(logging.WARNING, logger="teachfit.learning.runner"):
        report = run_study(study, pid_cost, 4, workers=1000, on_trial=count)
    assert report.finished == 4 and report.workers == 4
    assert len(alive) == 4 and 1 <= max(alive) <= 4
    pids = {t.info["pid"] for t in study.trials()}
    assert 1 <= len(pids) <= 4 and os.getpid() not in pids  # in worker processes, at most 4
    notes = [r.getMessage() for r in caplog.records]
    assert len(notes) == 1 and "1000 workers asked: using 4 (4 trial(s) left" in notes[0]
    study.close()
