"""The cell checks in simulation: aligned part enters, a part 1 mm off is blocked."""

from __future__ import annotations

from teachfit.robot.cell_checks import run_cell_checks
from teachfit.tasks.registry import load_task


def test_both_examples_pass_their_cell_checks(mesh_examples) -> None:
    for path in mesh_examples.values():
        checks = run_cell_checks(load_task(path))
        assert [c.passed for c in checks] == [True, True, True], checks
        assert checks[0].depth > 0.006 and max(c.depth for c in checks[1:]) < 2e-4
