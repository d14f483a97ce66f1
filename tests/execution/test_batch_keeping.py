"""A sequence of executions cut short keeps what finished (``execution.batch.Finished``), and the
run log written from it holds every finished execution."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import pytest
from run_logs import hand_made

from teachfit.core.errors import ConnectionLost, ReflexFault
from teachfit.core.outcome import Outcome
from teachfit.execution.batch import Finished, keeping, run_batch_keeping
from teachfit.execution.engine import ExecutionResult
from teachfit.execution.recording import RunInfo, read_run_log, write_run_log


def _stopping_at(k: int, exc: BaseException) -> Callable[[int], ExecutionResult]:
    """``fn(i)``: a result for ``i < k``, then ``exc``."""

    def fn(i: int) -> ExecutionResult:
        if i >= k:
            raise exc
        return dataclasses.replace(hand_made(), reason=f"execution {i}")

    return fn


@pytest.mark.parametrize(
    "exc",
    [
        ConnectionLost("lost the connection to the robot"),
        KeyboardInterrupt(),
        SystemExit(143),
        ValueError("a bug"),
    ],
    ids=["connection-lost", "ctrl-c", "sigterm", "bug"],
)
def test_a_run_cut_short_after_k_executions_keeps_those_k(exc: BaseException) -> None:
    done = []
    finished = run_batch_keeping(_stopping_at(3, exc), range(6), 0, lambda: done.append(1))
    assert [r.reason for r in finished.items] == ["execution 0", "execution 1", "execution 2"]
    assert len(done) == 3
    assert finished.stop is exc and not finished.complete and finished.total == 6


def test_a_run_that_completes_has_no_stop() -> None:
    finished = run_batch_keeping(_stopping_at(9, KeyboardInterrupt()), range(4), 0)
    assert len(finished.items) == 4 and finished.complete and finished.stop is None


def test_keeping_holds_what_a_callback_added_before_the_fault() -> None:
    finished: Finished[int] = Finished(total=5)
    with keeping(finished):
        for i in range(5):
            if i == 2:
                raise ReflexFault("cartesian_reflex")
            finished.add(i)
    assert finished.items == [0, 1] and isinstance(finished.stop, ReflexFault)


def test_the_run_log_of_an_interrupted_run_holds_every_finished_execution(tmp_path) -> None:
    fault = dataclasses.replace(hand_made(), outcome=Outcome.FAULT, reason="reflex")
    finished = run_batch_keeping(lambda i: fault if i == 1 else hand_made(), [0, 1, 2], 0)
    finished_too = run_batch_keeping(_stopping_at(2, KeyboardInterrupt()), range(5), 0)
    info = RunInfo("skill", "peg2d", "franka", 0, "peg-in-hole adaptive")
    path = write_run_log(tmp_path / "k.h5", finished_too.items, info)
    run = read_run_log(path)
    assert [ep.result.reason for ep in run.episodes] == ["execution 0", "execution 1"]
    path = write_run_log(tmp_path / "f.h5", finished.items, info)
    assert [ep.result.outcome for ep in read_run_log(path).episodes] == [
        Outcome.ERROR_CONDITION,
        Outcome.FAULT,
        Outcome.ERROR_CONDITION,
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.h5", "k.h5"]  # no temporary left


def test_worker_processes_keep_the_results_before_the_job_that_failed() -> None:
    finished = run_batch_keeping(math.sqrt, [4.0, 9.0, -1.0, 16.0, 25.0], workers=2)
    assert finished.items == [2.0, 3.0] and finished.total == 5
    assert isinstance(finished.stop, ValueError)


def test_keep_each_keeps_what_a_callback_run_finished_before_it_was_cut() -> None:
    from teachfit.execution.batch import keep_each

    ticks: list[int] = []

    def run(done: Callable[[int], None]) -> None:
        for i in range(3):
            if i == 2:
                raise KeyboardInterrupt
            done(i)

    finished = keep_each(5, run, lambda: ticks.append(1))
    assert finished.items == [0, 1] and finished.total == 5 and len(ticks) == 2
    assert isinstance(finished.stop, KeyboardInterrupt) and not finished.complete
    assert keep_each(1, lambda done: done("x")).complete
