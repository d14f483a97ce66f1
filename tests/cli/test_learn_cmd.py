"""``teachfit learn skill``: the skill objective in workers, resume, kills, mismatches."""

from __future__ import annotations

import pickle
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

from media_checks import read_png
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.learning import Study, run_study
from teachfit.learning.objective import SkillObjective
from teachfit.learning.study import stored_tags
from teachfit.skills import read_params_toml

runner = CliRunner()
QUICK = ["--task", "puzzle", "--starts", "1", "--method", "cmaes"]


def cli(*args: object) -> object:
    return runner.invoke(app, ["learn", "skill", *[str(a) for a in args]])


def _puzzle_study(db: Path, obj: SkillObjective) -> Study:
    """The stored CMA-ES puzzle study of ``QUICK`` (resumed, not run)."""
    return Study(
        db,
        task="puzzle",
        skill="peg-in-hole",
        space=obj.space,
        method="cmaes",
        penalty=obj.penalty,
        context=obj.context(),
    )


def test_skill_objective_runs_in_worker_processes_and_stores_sim_time(tmp_path: Path) -> None:
    obj = SkillObjective("puzzle", seed=1, n_starts=1)
    assert pickle.loads(pickle.dumps(obj)) == obj
    space = obj.space
    assert "force" in space.names and "alpha_t" in space.names  # skill + adaptive controller
    direct = obj(space.from_unit([0.5] * space.dim))
    study = Study(
        tmp_path / "s.db",
        task="puzzle",
        skill="peg-in-hole",
        space=space,
        method="lhs",
        seed=1,
        options={"n": 4},
        penalty=obj.penalty,
        context=obj.context(),
    )
    report = run_study(study, obj, 4, workers=2)
    recs = study.trials()
    assert report.finished == 4 and report.failed == 0 and len(recs) == 4
    for r in recs:
        assert 0.0 < r.cost < obj.penalty
        assert 0.5 < r.info["sim_s"] < 12.0  # one execution: skill + recovery, simulated s
        assert r.info["success_rate"] in (0.0, 1.0)
        assert r.feasible == (r.info["success_rate"] > 0)
    assert direct.feasible and direct.info["sim_s"] > 0.5
    assert obj.penalty > 5.0  # beyond every ordinary failure (t_max + k_d * d, d < roi)


def test_learn_skill_writes_the_best_params_and_its_figures(tmp_path: Path) -> None:
    """The command's wiring: a study run, the best parameters file and both figures; resuming
    and refusing a mismatched study are checked at the launch layer (tests/learning)."""
    db, best = tmp_path / "runs" / "p.db", tmp_path / "best.toml"
    out = [tmp_path / "c.png", tmp_path / "t.png"]
    res = cli(*QUICK, "--trials", 3, "--study", db, "--workers", 0, "--out", best,
              "--plot", out[0], "--traces", out[1])  # fmt: skip
    assert res.exit_code == 0, res.output
    for png in out:
        read_png(png, min_px=200)
    obj = SkillObjective("puzzle", n_starts=1)
    stored = _puzzle_study(db, obj).best()
    assert f"best: trial {stored.number + 1}, cost {stored.cost:.3f} s" in res.output
    # the parameter file holds exactly the best trial's values, and reads back as the skill's
    params = read_params_toml(best, obj.trial().setup.skill.params)
    assert set(params) == set(obj.space.names)
    assert params == {k: float(v) for k, v in stored.params.items()}
    res = cli(*QUICK, "--trials", 4, "--study", db, "--workers", 0)
    assert res.exit_code == 2 and "already has 3 trials" in res.output and "--resume" in res.output


def _stored(db: Path) -> int:
    try:
        with sqlite3.connect(db) as con:
            q = "SELECT count(*) FROM trials WHERE state = 'COMPLETE'"
            return int(con.execute(q).fetchone()[0])
    except sqlite3.OperationalError:  # Optuna has not created its tables yet
        return 0


def test_sigterm_mid_study_stops_cleanly_and_resume_loses_nothing(tmp_path: Path) -> None:
    db = tmp_path / "k.db"
    exe = Path(sys.executable).with_name("teachfit")
    proc = subprocess.Popen(
        [
            str(exe),
            "learn",
            "skill",
            *QUICK,
            "--trials",
            "300",
            "--study",
            str(db),
            "--workers",
            "1",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        # wait for 2 stored trials however long that takes on this machine (no deadline: the
        # loop also ends if the study process exits, e.g. on an error)
        while proc.poll() is None and (not db.exists() or _stored(db) < 2):
            time.sleep(0.2)
        proc.send_signal(signal.SIGTERM)
        out, _ = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, out
    assert "stopped" in out and "--resume" in out
    n1 = _stored(db)
    assert 2 <= n1 < 300
    tags = stored_tags(db)
    assert tags is not None and tags["method"] == "cmaes" and tags["task"] == "puzzle"
    obj = SkillObjective("puzzle", n_starts=1)
    kw = dict(
        task="puzzle",
        skill="peg-in-hole",
        space=obj.space,
        method="cmaes",
        options={},
        penalty=obj.penalty,
        context=obj.context(),
    )
    before = [(r.key, r.cost) for r in Study(db, **kw).trials()]  # type: ignore[arg-type]
    res = cli(*QUICK, "--trials", n1 + 1, "--study", db, "--workers", 0, "--resume")
    assert res.exit_code == 0, res.output
    after = Study(db, **kw).trials()  # type: ignore[arg-type]
    assert len(after) == n1 + 1 and len({r.key for r in after}) == n1 + 1
    assert [(r.key, r.cost) for r in after[:n1]] == before


def test_bad_method_or_task_creates_no_study_and_lhs_cannot_grow(tmp_path: Path) -> None:
    db = tmp_path / "runs" / "x.db"
    res = cli("--task", "puzzle", "--method", "nope", "--study", db)
    assert res.exit_code == 2 and "unknown learning method" in res.output
    res = cli("--task", "nope", "--study", db)
    assert res.exit_code == 2 and "unknown task" in res.output
    assert not db.exists() and stored_tags(db) is None and not db.exists()
    lhs = ["--task", "puzzle", "--starts", "1", "--method", "lhs", "--workers", 0]
    assert cli(*lhs, "--trials", 2, "--study", db).exit_code == 0
    res = cli(*lhs, "--trials", 4, "--study", db, "--resume")
    assert res.exit_code == 2 and "Latin hypercube has 2 points" in res.output
    res = cli(*lhs, "--trials", 2, "--study", db, "--resume")
    assert res.exit_code == 0 and "nothing to run" in res.output
