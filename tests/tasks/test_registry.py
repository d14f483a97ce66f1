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
