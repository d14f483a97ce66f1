"""The task registry: names, search dimensions, and where models take them from."""

from __future__ import annotations

import pytest

from teachfit.core.errors import ModelError, TaskError
from teachfit.models.search_data import dims_for_task
from teachfit.tasks import TASKS, get_task, search_dims_of


@pytest.mark.parametrize("name", sorted(TASKS))
def test_every_task_has_search_dims(name: str) -> None:
    dims = search_dims_of(name)
    assert dims[:2] == ("x", "y") and set(dims) <= {"x", "y", "rz"}
    assert dims == get_task(name).search_dims == dims_for_task(name)
    task = get_task(name)
    assert task.protocol.task is task and task.scene.task is task


def test_search_dims_of_the_five_tasks() -> None:
    assert {n: len(search_dims_of(n)) for n in TASKS} == {
        "peg2d": 2,
        "peg": 2,
        "socket3d": 3,
        "puzzle": 3,
        "key": 3,
    }
    with pytest.raises(TaskError, match="built-in tasks"):
        search_dims_of("tenon")
    with pytest.raises(ModelError, match="unknown task 'tenon'"):
        dims_for_task("tenon")


@pytest.mark.parametrize(
    ("line", "match"),
    [
        ('clearance = "abc"', "'clearance' must be a number, got 'abc'"),
        ("clearance = [1, 2]", "'clearance' must be a number"),
        ("clearance = {a = 1}", "'clearance' must be a number"),
        ("clearance = true", "'clearance' must be a number, got True"),
        ("friction = nan", "'friction' must be a finite number"),
        ("n_sectors = 12.9", "'n_sectors' must be a whole number, got 12.9"),
    ],
)
def test_task_file_values_of_the_wrong_type_are_refused(tmp_path, line: str, match: str) -> None:
    from teachfit.tasks.registry import load_task

    path = tmp_path / "bad.toml"
    path.write_text(f'task = "peg2d"\n{line}\n')
    with pytest.raises(TaskError, match=f"task file {path}: peg2d parameter {match}"):
        load_task(str(path))


def test_task_file_that_is_binary_or_whole_numbers_as_floats(tmp_path) -> None:
    from teachfit.tasks.registry import load_task

    path = tmp_path / "bin.toml"
    path.write_bytes(bytes(range(128, 256)))
    with pytest.raises(TaskError, match="is not a text"):
        load_task(str(path))
    path.write_text('task = "peg2d"\nn_sectors = 16.0\nclearance = 1e-3\n')
    task = load_task(str(path))
    assert task.params.n_sectors == 16 and isinstance(task.params.n_sectors, int)
