"""Teacher hints: typed overrides, merged with the later hints winning."""

from __future__ import annotations

import dataclasses

import pytest

from teachfit.core.teaching import NO_TEACHER_HINTS, TeacherHints
from teachfit.execution.teacher_style import TeacherStyle


def test_hints_name_only_style_fields():
    style_fields = {f.name for f in dataclasses.fields(TeacherStyle)}
    assert {f.name for f in dataclasses.fields(TeacherHints)} <= style_fields


def test_later_hints_win_and_none_leaves_a_field_alone():
    task = TeacherHints(speed=0.008, spiral_pitch=0.001)
    robot = TeacherHints(speed=0.006, press_feel=0.15)
    merged = task.then(robot)
    assert merged.overrides() == {"speed": 0.006, "spiral_pitch": 0.001, "press_feel": 0.15}
    assert task.then(NO_TEACHER_HINTS) == task
    assert NO_TEACHER_HINTS.overrides() == {}


def test_hints_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(NO_TEACHER_HINTS, "speed", 1.0)  # noqa: B010
