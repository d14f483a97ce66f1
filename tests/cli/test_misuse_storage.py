"""A misuse walk over study storages and worker counts: odd characters in study file names,
URLs with unknown schemes or missing drivers, URLs told from paths, and worker counts out of
range. A refusal is exit status 2 and one line naming the input, no traceback, and nothing
written; an accepted odd name writes the study and its parameters exactly at the names given,
and nothing else."""

from __future__ import annotations

import importlib.util
from collections.abc import Callable
from pathlib import Path

import pytest
from click.testing import Result
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.learning.base import TrialResult
from teachfit.learning.runner import RunReport
from teachfit.learning.study import Study, TrialRecord

runner = CliRunner()
LEARN = ["learn", "skill", "--task", "puzzle", "--starts", "1", "--method", "lhs", "--trials", "1"]

#: (arguments, what the one line must say): storages that can hold no study
STORAGES = [
    (["--study", "nosuch://x"], "unknown database scheme 'nosuch'"),
    (["--study", "oracle://u@h/db"], "unknown database scheme 'oracle'"),
    (["--study", "mysql+nosuchdriver://u@h/db"], "no driver 'nosuchdriver' for mysql"),
    (["--study", "postgresql+asyncpg://u@h/db"], "asyncio driver"),
    (["--study", "sqlite://"], "in-memory"),
    (["--study", "mysql://u@h:port/db"], "not a database URL"),
    (["--study", "runs/"], "is a folder"),
]
if importlib.util.find_spec("MySQLdb") is None:
    STORAGES.append((["--study", "mysql://u:pw@h/db"], "pip install mysqlclient"))
if importlib.util.find_spec("psycopg2") is None:
    STORAGES.append((["--study", "postgresql+psycopg2://u@h/db"], "pip install psycopg2-binary"))

#: (command, arguments, what the one line must say): worker counts and Ray set-ups refused
WORKERS = [
    (LEARN, ["--workers", "-1"], "--workers -1: give an integer >= 0"),
    (LEARN, ["--workers", "-1000"], "--workers -1000: give an integer >= 0"),
    (LEARN, ["--workers", "0", "--ray", "local"], "--workers 0 runs trials in this process"),
    (LEARN, ["--ray", "nowhere"], "HOST:PORT, got 'nowhere'"),
    (LEARN, ["--ray", "h:99999"], "HOST:PORT, got 'h:99999'"),
    (["bench", "learning", "--scaling"], ["--workers", "-2"], "--workers -2: give an integer"),
    (["bench", "search"], ["--workers", "-1"], "--workers -1: give an integer >= 0"),
]


def _files(root: Path) -> list[str]:
    return sorted(str(p.relative_to(root)) for p in root.rglob("*"))


def _refused_in_one_line(res: Result, says: str) -> None:
    out = res.output.strip()
    assert res.exit_code == 2, out
    assert "Traceback" not in out and len(out.splitlines()) == 1, out
    assert out.startswith("error: ") and says in out, out


@pytest.mark.parametrize(("args", "says"), STORAGES)
def test_a_storage_that_cannot_hold_a_study_is_refused_in_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, args: list[str], says: str
) -> None:
    monkeypatch.chdir(tmp_path)
    if args[1] == "runs/":
        (tmp_path / "runs").mkdir()
    before = _files(tmp_path)
    res = runner.invoke(app, [*LEARN, *args])
    _refused_in_one_line(res, says)
    assert "pw@" not in res.output  # a password is never echoed
    assert _files(tmp_path) == before


@pytest.mark.parametrize(("command", "args", "says"), WORKERS)
def test_a_worker_count_out_of_range_is_refused_in_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, command: list[str], args: list[str], says: str
) -> None:
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(app, [*command, *args])
    _refused_in_one_line(res, says)
    assert _files(tmp_path) == []


def _one_trial(
    study: Study,
    objective: object,
    budget: int,
    workers: int | None = None,
    on_trial: Callable[[TrialRecord], None] | None = None,
) -> RunReport:
    """Stands in for the trials (this walk is about where the study goes): one stored trial."""
    cand = study.ask(budget)
    if cand is None:
        return RunReport(study.n_finished, 0, 0, False, 1.0)
    rec = study.tell(cand, TrialResult(2.0, True, {"success_rate": 1.0}))
    if rec is not None and on_trial is not None:
        on_trial(rec)
    return RunReport(0, 1, 0, False, 1.0)


@pytest.mark.parametrize("name", ["a?b.db", "50%41.db", "c#d e.db", "x://y.db"])
def test_an_odd_study_file_name_is_a_file_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str
) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("teachfit.learning.runner.run_study", _one_trial)
    typed = f"runs/{name}"  # as typed; 'x://y.db' is a path too (a URL starts with its scheme)
    res = runner.invoke(app, [*LEARN, "--workers", "0", "--study", typed])
    assert res.exit_code == 0, res.output
    study, params = Path(typed), Path(typed).with_suffix(".params.toml")
    assert f"parameters -> {params}" in res.output
    folders = {str(p) for p in study.parents if str(p) != "."}
    assert _files(tmp_path) == sorted({str(study), str(params), *folders})
    res = runner.invoke(app, [*LEARN, "--workers", "0", "--study", typed, "--resume"])
    assert res.exit_code == 0 and "1 trial(s) restored" in res.output, res.output
    assert _files(tmp_path) == sorted({str(study), str(params), *folders})
