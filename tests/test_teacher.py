import numpy as np
import pytest

from teachfit.demonstrations.teacher import BlindTeacher, TeacherStyle
from teachfit.errors import TeachfitError
from teachfit.tasks import get_task


def test_teacher_demos_succeed_and_look_kinesthetic():
    task = get_task("peg2d")
    demos, _ = BlindTeacher(task, seed=1).record(2)
    for demo in demos:
        assert demo.source == "simulated-teacher" and demo.task == "peg2d"
        assert demo.rate_hz == pytest.approx(100.0, rel=0.01)
        assert task.is_inserted(type(task.hole2world)(demo.pos[-1], demo.quat[-1]))
        start = demo.pos[0, :2]
        assert np.linalg.norm(start) == pytest.approx(task.params.demo_offset, abs=0.002)
        # kept contact: pressing on the surface most of the time
        assert np.median(demo.wrench[:, 2]) > 3.0
        assert np.all(np.isfinite(demo.wrench))


def test_same_seed_same_demo():
    task = get_task("peg2d")
    a, _ = BlindTeacher(task, seed=7).record(1)
    b, _ = BlindTeacher(task, seed=7).record(1)
    assert np.array_equal(a[0].pos, b[0].pos)


def test_demos_that_end_at_once_or_never_are_discarded():
    task = get_task("peg2d")
    teacher = BlindTeacher(task, seed=0)
    demo, why = teacher.demonstrate(task.contact_pose([0.0, 0.0]).translated([0, 0, 0.001]))
    assert demo is None and "at once" in why
    lazy = BlindTeacher(task, TeacherStyle(max_duration=0.6, min_duration=0.1), seed=0)
    demo, why = lazy.demonstrate()
    assert demo is None and "never" in why
    with pytest.raises(TeachfitError, match="succeeded"):
        lazy.record(1, max_attempts=2)
