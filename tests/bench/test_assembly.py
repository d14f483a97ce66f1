"""``bench assembly``: every method on the same trials, and where the joined one loses."""

from search_models import raster_model

from teachfit.bench.assembly import bench_task, losses
from teachfit.metrics.stats import summarize
from teachfit.tasks import get_task


def test_losses_names_lower_rates_and_slower_ties():
    s = lambda ok, t: summarize(ok, t)  # noqa: E731
    rows = {
        "skill": [(0.0, s([True, True], [1.0, 1.0])), (0.003, s([True, False], [1.0, 9.0]))],
        "joined": [(0.0, s([True, True], [2.0, 2.0])), (0.003, s([True, True], [3.0, 3.0]))],
    }
    out = losses(rows)
    assert len(out) == 1 and out[0].startswith("skill at 0 mm on time")


def test_bench_task_runs_each_method_on_the_same_trials():
    task = get_task("peg2d")
    rows = bench_task(
        "peg2d", [0.0], 1, workers=0, methods=("skill", "open-loop"), model=raster_model(task)
    )
    assert set(rows) == {"skill", "open-loop"}
    for pts in rows.values():
        ((err, summary),) = pts
        assert err == 0.0 and summary.trials == 1 and summary.successes == 1


def test_learned_parameters_add_a_joined_learned_row(tmp_path):
    import pytest

    from teachfit.bench.assembly import bench_inputs
    from teachfit.core.errors import TeachfitError

    task = get_task("peg2d")
    model = raster_model(task)
    path = tmp_path / "peg.model"
    model.save(path)
    params = tmp_path / "best.toml"
    params.write_text("[params]\nt_switch = 0.4\nsearch_points = 30\n", encoding="utf-8")
    got, learned = bench_inputs(["peg2d"], path, params)
    assert got is not None and (learned["t_switch"], learned["search_points"]) == (0.4, 30.0)
    with pytest.raises(TeachfitError, match="exactly one"):
        bench_inputs(["peg2d", "socket3d"], path, None)
    rows = bench_task("peg2d", [0.0], 1, workers=0, methods=(), model=got, learned=learned)
    assert list(rows) == ["joined-learned"] and rows["joined-learned"][0][1].successes == 1
