"""The FR3 speed benchmark runs and reports sane figures (timings are printed, not asserted)."""

from teachfit.robot.speed import ArmSimSpeed, measure_sim_speed
from teachfit.tasks import get_task


def test_fr3_speed_benchmark_reports_both_loops_in_contact():
    speed = measure_sim_speed(get_task("peg2d"), steps=100, repeats=1, robot="fr3")
    assert isinstance(speed, ArmSimSpeed)
    assert speed.contacts > 0  # measured while the part is pressed onto the block
    assert speed.raw_steps_per_s > 0 and speed.controlled_steps_per_s > 0
    assert speed.ratio == speed.controlled_steps_per_s / speed.raw_steps_per_s
    assert 0 < speed.compute_p50_us <= speed.compute_p99_us
    print(speed)
