"""Parametric parts of the planning tasks."""

import pytest

from teachfit.core.errors import TaskError
from teachfit.plans import PARTS, CollisionChecker, LGrooveParams, TenonParams, build_assembly


@pytest.mark.parametrize("task", sorted(PARTS))
def test_default_parts_are_watertight_with_free_start_and_goal(task):
    asm = build_assembly(task)
    assert asm.task == task
    assert asm.moving.is_watertight and asm.fixed.is_watertight
    checker = CollisionChecker(asm.moving, asm.fixed)
    assert not checker.collides(asm.start)
    assert not checker.collides(asm.goal)
    assert (asm.bounds[0] <= asm.start[:3, 3]).all() and (asm.start[:3, 3] <= asm.bounds[1]).all()
    assert (asm.bounds[0] <= asm.goal[:3, 3]).all() and (asm.goal[:3, 3] <= asm.bounds[1]).all()


def test_l_groove_opening_is_shorter_than_the_base():
    asm = build_assembly("l-groove")
    dims = asm.dimensions
    assert dims["opening_length"] < dims["base_length"] < dims["cavity_length"]
    # the goal pose fits with the clearance on both sides across the groove
    gap = CollisionChecker(asm.moving, asm.fixed).distance(asm.goal)
    assert gap == pytest.approx(dims["clearance"], abs=1e-4)


def test_dimension_overrides_change_the_meshes():
    wide = build_assembly("l-groove", width=0.04)
    assert wide.moving.extents[1] == pytest.approx(0.04)


@pytest.mark.parametrize(
    ("cls", "kwargs"),
    [
        (LGrooveParams, {"base_length": -0.1}),
        (LGrooveParams, {"opening_length": 0.12}),
        (LGrooveParams, {"cavity_depth": 0.005}),
        (LGrooveParams, {"clearance": float("nan")}),
        (TenonParams, {"shoulder_side": 0.015}),
        (TenonParams, {"bar_length": 0.05}),
    ],
)
def test_invalid_dimensions_raise_task_error(cls, kwargs):
    with pytest.raises(TaskError):
        cls(**kwargs)


def test_unknown_task_or_dimension_raises():
    with pytest.raises(TaskError, match="unknown task"):
        build_assembly("peg")
    with pytest.raises(TaskError, match="unknown dimension"):
        build_assembly("tenon", colour=1.0)


def test_the_registry_knows_every_task_and_builds_every_assembly() -> None:
    from teachfit.tasks.registry import TASKS, build_assembly, part_tables, task_names

    names = task_names()
    assert set(names) == set(TASKS) | set(PARTS)
    assert [n for n, _ in part_tables()["tenon"]][0] == "bar_side"
    assert build_assembly("tenon", clearance=0.002).dimensions["clearance"] == 0.002
    with pytest.raises(TaskError, match="no overrides"):
        build_assembly("mine.toml", width=0.01)
