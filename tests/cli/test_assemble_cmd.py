"""``teachfit assemble`` through typer's CliRunner."""

import pytest
from media_checks import read_png
from search_models import raster_model
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.cli.assemble_cmd import parse_quantity
from teachfit.core.errors import TeachfitError
from teachfit.execution.recording import read_run_log
from teachfit.tasks import get_task

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def peg_model(tmp_path_factory):
    return raster_model(get_task("peg2d")).save(tmp_path_factory.mktemp("models") / "peg.model")


def test_parse_quantity_reads_units():
    assert parse_quantity("3mm") == pytest.approx(0.003)
    assert parse_quantity("0.5 cm") == pytest.approx(0.005)
    assert parse_quantity("2") == pytest.approx(0.002)
    assert parse_quantity("90deg", "deg") == pytest.approx(1.5707963)
    with pytest.raises(TeachfitError, match="--hole-error"):
        parse_quantity("3 furlongs")


def test_assemble_reports_success_and_plots_the_phases(tmp_path, peg_model):
    model = peg_model
    png = tmp_path / "phases.png"
    res = invoke(
        "assemble", "--task", "peg2d", "--search", model, "--hole-error", "0mm",
        "--trials", 1, "--plot", png, "--log", tmp_path / "run.h5",
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "success 1/1 = 100 %" in res.output and "[21, 100] %" in res.output
    assert "lateral" in res.output
    read_png(png)
    run = read_run_log(tmp_path / "run.h5")  # the run log: one episode, its outcome
    assert run.info.kind == "assemble" and len(run.episodes) == 1
    assert run.episodes[0].result.success


def test_assemble_bad_input_is_one_line_and_exit_2(peg_model):
    res = invoke("assemble", "--task", "peg2d", "--hole-error", "3 furlongs")
    assert res.exit_code == 2 and "cannot read '3 furlongs'" in res.output
    res = invoke("assemble", "--task", "socket3d", "--search", peg_model, "--trials", 1)
    assert res.exit_code == 2 and "learned for task 'peg2d'" in res.output
    assert "Traceback" not in res.output


def test_assemble_matches_a_model_to_a_task_file_as_search_run_does(tmp_path, peg_model):
    # a model learned on peg2d records 'peg2d'; a task file of kind peg2d is that task, so
    # assemble accepts the model as search run does (it once asked for the file's name)
    task_file = tmp_path / "mypeg.toml"
    task_file.write_text('task = "peg2d"\n', encoding="utf-8")
    res = invoke(
        "assemble", "--task", task_file, "--search", peg_model, "--hole-error", "0mm",
        "--trials", 1,
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "success 1/1" in res.output
    other = tmp_path / "mysocket.toml"
    other.write_text('task = "socket3d"\n', encoding="utf-8")
    res = invoke("assemble", "--task", other, "--search", peg_model, "--trials", 1)
    assert res.exit_code == 2 and "learned for task 'peg2d', not 'socket3d'" in res.output


def test_assemble_l_groove_with_a_missing_demo_is_one_line(tmp_path):
    res = invoke("assemble", "--task", "l-groove", "--demo", tmp_path / "none.h5", "--trials", 1)
    assert res.exit_code == 2 and "none.h5" in res.output and "Traceback" not in res.output


def test_bench_assembly_params_are_checked_before_any_trial(tmp_path, peg_model):
    bad = tmp_path / "bad.toml"
    bad.write_text("t_switch = 99.0\n", encoding="utf-8")
    res = invoke("bench", "assembly", "--tasks", "peg2d", "--search", peg_model, "--params", bad)
    assert res.exit_code == 2 and "bad.toml" in res.output and "Traceback" not in res.output
    res = invoke("bench", "assembly", "--tasks", "peg2d,socket3d", "--search", peg_model)
    assert res.exit_code == 2 and "exactly one peg-type task" in res.output


def test_bench_assembly_appends_its_table_as_markdown(tmp_path, monkeypatch):
    from teachfit.bench import assembly
    from teachfit.metrics.stats import summarize

    def bench_task(name, errors, trials, *args, **kwargs):
        ok, none = summarize([True, True, False], [1.5, 2.5, 9.0]), summarize([False], [0.0])
        return {"skill": [(e, ok) for e in errors], "joined": [(e, none) for e in errors]}

    monkeypatch.setattr(assembly, "bench_task", bench_task)
    out = tmp_path / "assembly.md"
    res = invoke("bench", "assembly", "--tasks", "peg2d", "--errors", "0,3", "--markdown", out)
    assert res.exit_code == 0, res.output
    text = out.read_text(encoding="utf-8")
    assert text.startswith("<!-- teachfit-run source=command")
    assert "| peg2d (10 trials), e (mm) | skill | joined |" in text
    assert "| 3 | 2/3 [21,94] 2.00 | 0/1 [0,79] |" in text


def test_bench_assembly_on_the_arm_names_it_and_refuses_a_real_robot(tmp_path, monkeypatch):
    from teachfit.bench import assembly, search
    from teachfit.metrics.stats import summarize

    seen = []

    def bench_task(name, errors, trials, *args, **kwargs):
        seen.append(search.ROBOT[0])
        return {"skill": [(e, summarize([True], [1.0])) for e in errors]}

    monkeypatch.setattr(assembly, "bench_task", bench_task)
    monkeypatch.setattr(search, "ROBOT", ["floating"])
    out = tmp_path / "assembly.md"
    res = invoke("bench", "assembly", "--robot", "fr3", "--errors", "0", "--markdown", out)
    assert res.exit_code == 0, res.output
    assert seen == ["fr3", "fr3"]
    assert "| socket3d on fr3 (10 trials), e (mm) | skill |" in out.read_text(encoding="utf-8")
    res = invoke("bench", "assembly", "--robot", "franka", "--errors", "0")
    assert res.exit_code == 2 and "choose floating or fr3" in res.output
