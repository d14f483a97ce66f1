"""The peg-in-hole skill with its default parameters inserts a sharp-edged tight part."""

from __future__ import annotations

from teachfit.execution import peg_in_hole_setup
from teachfit.execution.skill_trial import SkillTrial
from teachfit.tasks import get_task


def test_the_round_peg_example_inserts_with_the_defaults(mesh_examples: dict[str, str]) -> None:
    """Ø 8 mm, no chamfer, 0.1 mm per side, the taught hole off by (0.17, 0.41) mm (four
    times the clearance across the move): the low rim leads, drops over the hole, is centred
    and caught by the far wall, and turned upright into the hole."""
    setup = peg_in_hole_setup(get_task(mesh_examples["round-peg"]), seed=1, n_starts=1)
    trial = SkillTrial(setup)
    try:
        result = trial.run(None, setup.starts[0])
    finally:
        trial.robot.close()
    assert [v.node for v in result.visits] == ["approach", "contact", "lateral", "align", "insert"]
    assert result.success and result.ground_truth_inserted
