"""The parts bench on a real part, at the smallest size."""

from __future__ import annotations

from pathlib import Path

import pytest

from teachfit.bench import parts as bp
from teachfit.core.errors import TeachfitError
from teachfit.tasks.mesh.suite import write_suite


@pytest.fixture(scope="module")
def round12(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The round 12 mm chamfered part's meshes and task file, written once for the tests that
    search it."""
    (task,) = write_suite(tmp_path_factory.mktemp("suite"), ["round12-chamfer-blind"])
    return Path(task)


def test_the_default_skill_runs_on_held_out_setups_of_a_suite_part(tmp_path: Path) -> None:
    (task,) = write_suite(tmp_path, ["rect12x8-sharp-through"])
    ticks = []
    rows = bp.bench_part(
        "rect12x8", task, "floating", bp.Sizes(setups=1), methods=["skill"],
        progress=lambda: ticks.append(1),
    )  # fmt: skip
    (row,) = rows
    assert (row.part, row.robot, row.method) == ("rect12x8", "floating", "skill")
    assert row.summary.trials == 1 and 0.0 <= row.summary.low <= row.summary.high <= 1.0
    assert len(row.failures) == 1 - row.summary.successes  # each failure with its reason
    assert all(": " in why for why in row.failures)
    assert len(ticks) == bp.Sizes(setups=1).units(["skill"]) == 1


def test_search_and_assemble_run_on_the_robot_asked_for(round12: Path) -> None:
    from teachfit.bench import search as bs

    task = round12
    sizes = bp.Sizes(starts=1, points=10)
    rows = bp.bench_part("round12", task, "fr3", sizes, methods=["search", "assemble"])
    assert [(r.robot, r.method, r.summary.trials) for r in rows] == [
        ("fr3", "search", 1), ("fr3", "assemble", 1)
    ]  # fmt: skip
    assert all(len(r.failures) == 1 - r.summary.successes for r in rows)
    assert bs.ROBOT[0] == "floating"  # the search benches' robot is left as it was


def test_sizes_below_one_are_refused() -> None:
    with pytest.raises(TeachfitError, match="--train-setups must be >= 1"):
        bp.Sizes(train_setups=0)


def test_the_search_rows_come_from_the_same_starts_as_bench_search_task(round12: Path) -> None:
    from teachfit.bench.search_jobs import run_jobs
    from teachfit.bench.search_task import task_demos, task_jobs, task_table

    task = round12
    demos = task_demos(str(task), 0)
    res = run_jobs(task_jobs(str(task), demos, 0, n_starts=1, n_points=10), workers=0)
    rows = task_table(str(task), demos, 0, n_starts=1, n_points=10, workers=0)
    assert [r.method for r in rows] == ["tshix", "ergodic"]
    assert rows[0].ours.successes == sum(r.success for r in res)
    assert rows[0].length == pytest.approx(res[0].path_length)  # the same planned path
