"""Trials in worker processes: a crash, an exception or a divergence fails only that trial."""

from __future__ import annotations

import os
from pathlib import Path

from teachfit.learning import ParamDomain, ParamSpace, Study, run_study

SPACE = ParamSpace({"a": ParamDomain(0.0, 1.0), "b": ParamDomain(0.0, 1.0)})


def faulty(p: dict[str, float]) -> float:
    """Fine below a = 0.6; diverges (NaN), raises, or kills its worker process above."""
    a = p["a"]
    if a >= 0.9:
        os._exit(3)  # a worker that dies (segfault-like): no exception reaches the pool
    if a >= 0.75:
        raise ValueError("simulation blew up")
    if a >= 0.6:
        return float("nan")
    return (a - 0.3) ** 2 + (p["b"] - 0.5) ** 2


def test_crashing_raising_and_diverging_trials_do_not_stop_the_study(tmp_path: Path) -> None:
    study = Study(
        tmp_path / "faults.db",
        task="puzzle",
        skill="peg-in-hole",
        space=SPACE,
        method="lhs",
        seed=2,
        options={"n": 20},
        penalty=99.0,
    )
    report = run_study(study, faulty, 20, workers=2)
    trials = study.trials()
    assert report.finished == 20 and not report.interrupted
    assert len(trials) == 20 and len({t.key for t in trials}) == 20
    by_a = {t.key: t for t in trials}
    for t in by_a.values():
        a = t.params["a"]
        if a < 0.6:
            assert t.outcome == "ok" and t.cost < 1.0
        else:
            assert t.outcome == "error" and t.cost == 99.0 and not t.feasible
    crashed = [t for t in trials if "crashed" in t.error]
    assert len(crashed) == sum(t.params["a"] >= 0.9 for t in trials) == 2
    assert any("ValueError" in t.error for t in trials)
    assert any("non-finite" in t.error for t in trials)
    assert report.failed == sum(t.params["a"] >= 0.6 for t in trials) == 8
