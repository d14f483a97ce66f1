"""Issue 11's F/T smoothness figures as a check on short recordings, on both robots."""

import numpy as np
import pytest

from teachfit.bench.sensor import Smoothness, slide_smoothness
from teachfit.execution.teacher import TeacherStyle


def test_smoothness_figures_tell_white_from_slow():
    rng = np.random.default_rng(0)
    white = Smoothness.of(6.0 + rng.normal(0.0, 0.3, 2000))
    assert abs(white.lag1) < 0.1 and not white.meets_goal
    slow = Smoothness.of(6.0 + 0.3 * np.sin(np.arange(2000) * 0.01 * 2 * np.pi * 0.5))
    assert slow.lag1 > 0.99 and slow.meets_goal
    assert slow.mean == pytest.approx(6.0, abs=0.01)


@pytest.mark.parametrize("robot", ["floating", "fr3"])
def test_sliding_under_the_teachers_press_reads_like_a_real_sensor(robot):
    """4 s of sliding with the teacher's stiffness and slowly wandering press, recorded at
    100 Hz: std <= 0.5 N and lag-1 >= 0.9 (the former point-sampled first-order filter gave
    1.6 N and 0.0 on the floating tool), and the mean is the press."""
    s = slide_smoothness(robot, seed=0, duration=4.0, start_xy=(0.035, -0.024))
    assert s.n >= 400  # 4 s at 100 Hz
    assert 5.0 < s.mean < 7.0
    assert s.std <= 0.5
    assert s.lag1 >= 0.9


def test_without_the_press_wander_the_floating_tool_reads_a_flat_press():
    """What is left without the slow press is the filtered contact micro-chatter and gauge
    noise: a few hundredths of a newton, not the 1.6 N white signal of point samples."""
    s = slide_smoothness("floating", seed=0, duration=2.0, style=TeacherStyle(press_wander=0.0))
    assert abs(s.mean - 6.0) < 0.1
    assert s.std < 0.05
