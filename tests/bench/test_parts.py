"""The parts bench on a real part, at the smallest size."""

from __future__ import annotations

from pathlib import Path

import pytest

from teachfit.bench import parts as bp
from teachfit.core.errors import TeachfitError
from teachfit.tasks.mesh.suite import write_suite


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
    assert len(ticks) == bp.Sizes(setups=1).units(["skill"]) == 1


def test_sizes_below_one_are_refused() -> None:
    with pytest.raises(TeachfitError, match="--train-setups must be >= 1"):
        bp.Sizes(train_setups=0)
