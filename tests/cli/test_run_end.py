"""How a run on a robot ends (``cli.run_end``): each execution the robot stopped is named with
its reason, the exit status says how the run went, and a run cut short (a lost connection,
Ctrl-C) still prints and logs every finished execution (the wiring through ``skill run`` and
``search run``, with the robot's executions replaced by canned results)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import pytest
import typer
from click.testing import Result
from run_logs import hand_made
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.cli.run_end import MAX_LINES, end_run, report_faults
from teachfit.core.errors import ConnectionLost, ReflexFault, SkillError
from teachfit.core.outcome import Outcome
from teachfit.execution.batch import Finished
from teachfit.execution.engine import ExecutionResult
from teachfit.execution.recording import read_run_log

runner = CliRunner()


def _result(i: int, outcome: Outcome = Outcome.ERROR_CONDITION) -> ExecutionResult:
    return dataclasses.replace(hand_made(), outcome=outcome, reason=f"reason {i}")


def test_report_faults_names_each_stopped_execution_and_its_reason(capsys) -> None:
    rows = [
        (0, "success", "success condition"),
        (1, "robot-fault", "ReflexFault: cartesian_reflex"),
        (2, "timeout", "hard cap"),
        (3, "control-error", "stiffness over k_max"),
    ]
    assert report_faults(rows) is True
    out = capsys.readouterr().out.splitlines()
    assert out == [
        "execution 1 robot-fault: ReflexFault: cartesian_reflex",
        "execution 3 control-error: stiffness over k_max",
    ]


def test_report_faults_is_false_without_a_robot_fault_and_caps_its_lines(capsys) -> None:
    assert report_faults([(0, "success", ""), (1, "control-error", "k")]) is False
    capsys.readouterr()
    many = [(i, "diverged", f"nan at {i}") for i in range(MAX_LINES + 3)]
    assert report_faults(many, "trial") is True
    out = capsys.readouterr().out.splitlines()
    assert len(out) == MAX_LINES + 1 and out[0] == "trial 0 diverged: nan at 0"
    assert out[-1].startswith("... and 3 more")


@pytest.mark.parametrize(
    ("stop", "faulted", "status"),
    [
        (None, True, 1),
        (ConnectionLost("lost"), False, 1),
        (ReflexFault("reflex"), False, 1),
        (SkillError("bad"), False, 2),
        (KeyboardInterrupt(), False, 130),
        (SystemExit(143), False, 143),
    ],
)
def test_end_run_exit_status(stop: BaseException | None, faulted: bool, status: int) -> None:
    finished = Finished(items=[1, 2], total=5, stop=stop)
    with pytest.raises(typer.Exit) as err:
        end_run(finished, faulted)
    assert err.value.exit_code == status


def test_end_run_returns_for_a_clean_run_and_re_raises_a_bug() -> None:
    end_run(Finished(items=[1], total=1))
    bug = ValueError("a bug")
    with pytest.raises(ValueError, match="a bug"):
        end_run(Finished(items=[1], total=3, stop=bug))


class _NoRobot:
    """What ``make_robot`` gives here: nothing to drive (the executions are canned)."""

    name = "floating"

    def close(self) -> None:
        pass


def _skill_run(
    monkeypatch: pytest.MonkeyPatch, results: Callable[[int], ExecutionResult], *args: object
) -> Result:
    from teachfit.execution import skill_trial

    calls = iter(range(100))
    monkeypatch.setattr(skill_trial, "make_robot", lambda *a, **k: _NoRobot())
    monkeypatch.setattr(skill_trial.SkillTrial, "run", lambda self, *a: results(next(calls)))
    return runner.invoke(app, ["skill", "run", *map(str, args)])


def test_skill_run_cut_short_prints_and_logs_what_finished(monkeypatch, tmp_path) -> None:
    def results(i: int) -> ExecutionResult:
        if i == 2:
            raise ConnectionLost("lost the connection to the robot (UDP receive: Timeout)")
        return _result(i)

    log = tmp_path / "k.h5"
    res = _skill_run(monkeypatch, results, "--starts", 6, "--log", log)
    assert res.exit_code == 1, res.output
    assert "executions" in res.output and "run log -> " in res.output
    assert "stopped after 2 of 6 execution(s): lost the connection" in res.output
    assert "Traceback" not in res.output
    assert [ep.result.reason for ep in read_run_log(log).episodes] == ["reason 0", "reason 1"]


def test_skill_run_ctrl_c_keeps_the_log_and_exits_130(monkeypatch, tmp_path) -> None:
    def results(i: int) -> ExecutionResult:
        if i == 1:
            raise KeyboardInterrupt
        return _result(i)

    log = tmp_path / "k.h5"
    res = _skill_run(monkeypatch, results, "--starts", 3, "--log", log)
    assert res.exit_code == 130, res.output
    assert "stopped after 1 of 3 execution(s): interrupted (Ctrl-C)" in res.output
    assert len(read_run_log(log).episodes) == 1


def test_skill_run_with_a_robot_fault_prints_its_reason_and_exits_1(monkeypatch) -> None:
    res = _skill_run(
        monkeypatch, lambda i: _result(i, Outcome.FAULT if i == 1 else Outcome.TIMEOUT)
    )
    assert res.exit_code == 1, res.output
    assert "execution 1 robot-fault: reason 1" in res.output
    assert "execution 0 " not in res.output  # a timeout is the skill's own end: no line


def test_skill_run_interrupted_before_any_execution_writes_no_log(monkeypatch, tmp_path) -> None:
    def results(i: int) -> ExecutionResult:
        raise KeyboardInterrupt

    log = tmp_path / "k.h5"
    res = _skill_run(monkeypatch, results, "--starts", 2, "--log", log)
    assert res.exit_code == 130, res.output
    assert "no execution finished" in res.output and not log.exists()


def test_search_run_cut_short_keeps_its_finished_searches(monkeypatch, tmp_path) -> None:
    from search_models import raster_model

    from teachfit.core.setpoints import SetpointTrajectory
    from teachfit.execution import search
    from teachfit.robot import registry
    from teachfit.tasks import get_task

    model_file = tmp_path / "search.model"
    raster_model(get_task("peg2d")).save(model_file)
    planned = SetpointTrajectory.from_path(np.arange(3.0), np.zeros((3, 3)))

    def run_protocol(*args: object, on_done: Callable, **kw: object) -> list:
        for i in range(2):
            on_done(search.SearchRun(_result(i, Outcome.FAULT), None, planned))
        raise KeyboardInterrupt

    monkeypatch.setattr(search, "run_protocol", run_protocol)
    monkeypatch.setattr(registry, "make_robot", lambda *a, **k: _NoRobot())
    log = tmp_path / "s.h5"
    args = ["search", "run", "--model", model_file, "--starts", 5, "--log", log]
    res = runner.invoke(app, [str(a) for a in args])
    assert res.exit_code == 130, res.output
    assert "robot-fault 2" in res.output  # the table of the two that finished
    assert "execution 1 robot-fault: reason 1" in res.output
    assert "stopped after 2 of 5 execution(s): interrupted (Ctrl-C)" in res.output
    assert len(read_run_log(log).episodes) == 2


def _trial(i: int, reason: str) -> object:
    from teachfit.execution.assembly import AssemblyTrial

    ok = reason.startswith("success")
    return AssemblyTrial("skill", 0.003, i, ok, 1.0, None, (0.0, 0.0), (), reason, _result(i))


def test_assemble_with_a_robot_fault_prints_its_reason_and_exits_1(monkeypatch) -> None:
    from teachfit.execution import assembly

    reasons = ["success: success condition", "robot-fault: ReflexFault: cartesian_reflex"]
    monkeypatch.setattr(
        assembly, "run_assembly_job", lambda job: _trial(job.index, reasons[job.index])
    )
    res = runner.invoke(app, ["assemble", "--trials", "2"])
    assert res.exit_code == 1, res.output
    assert "trial 1 robot-fault: ReflexFault: cartesian_reflex" in res.output
    assert "trial 0 " not in res.output


def test_assemble_ctrl_c_keeps_the_finished_trials_in_its_log(monkeypatch, tmp_path) -> None:
    from teachfit.execution import assembly

    def job(job: assembly.AssemblyJob) -> object:
        if job.index == 2:
            raise KeyboardInterrupt
        return _trial(job.index, "timeout: hard cap")

    monkeypatch.setattr(assembly, "run_assembly_job", job)
    log = tmp_path / "a.h5"
    res = runner.invoke(app, ["assemble", "--trials", "4", "--log", str(log)])
    assert res.exit_code == 130, res.output
    assert "stopped after 2 of 4 trial(s): interrupted (Ctrl-C)" in res.output
    assert [ep.result.reason for ep in read_run_log(log).episodes] == ["reason 0", "reason 1"]


def test_assemble_in_contact_ctrl_c_keeps_the_finished_trials(monkeypatch, tmp_path) -> None:
    from types import SimpleNamespace

    from teachfit.execution import plan_contact as pc

    plan = SimpleNamespace(success=True, time_s=0.1, used_key_poses=2, candidates=3)

    def run_plan_trials(part: str, path: object, trials: int, seed: int, on_trial, **kw):
        for i in range(2):
            on_trial(pc.PlanTrial("joined", i, False, None, 1.0, 0.001, 0.01, _result(i)))
        raise KeyboardInterrupt

    monkeypatch.setattr(pc, "plan_path", lambda *a: plan)
    monkeypatch.setattr(pc, "timed_path", lambda *a: SimpleNamespace(duration=1.0))
    monkeypatch.setattr(pc, "run_plan_trials", run_plan_trials)
    log = tmp_path / "a.h5"
    res = runner.invoke(app, ["assemble", "--task", "l-groove", "--trials", "5", "--log", str(log)])
    assert res.exit_code == 130, res.output
    assert "stopped after 2 of 5 trial(s): interrupted (Ctrl-C)" in res.output
    assert len(read_run_log(log).episodes) == 2
