"""The seeded teacher's two peg2d demonstrations, as the quickstart records them.

Unlike ``test_teacher.py`` this module keeps the run's teacher cache: the recording (seed 1,
two demonstrations) is made once per run, by whichever of this test and the quickstart's
CLI test comes first, and checked here.
"""

import numpy as np
import pytest

from teachfit.execution.teacher import BlindTeacher
from teachfit.tasks import get_task


def test_teacher_demos_succeed_and_look_kinesthetic():
    task = get_task("peg2d")
    demos, _ = BlindTeacher(task, seed=1).record(2)
    for demo in demos:
        assert demo.source == "simulated-teacher" and demo.task == "peg2d"
        assert demo.rate_hz == pytest.approx(100.0, rel=0.01)
        assert task.ground_truth_inserted(type(task.hole2world)(demo.pos[-1], demo.quat[-1]))
        start = demo.pos[0, :2]
        assert np.linalg.norm(start) == pytest.approx(task.params.demo_offset, abs=0.002)
        # kept contact: pressing on the surface most of the time
        assert np.median(demo.wrench[:, 2]) > 3.0
        assert np.all(np.isfinite(demo.wrench))
