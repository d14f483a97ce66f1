"""The peg-in-hole skill with its default parameters inserts a sharp-edged tight part."""

from __future__ import annotations

from teachfit.execution import peg_in_hole_setup
from teachfit.execution.skill_trial import SkillTrial
from teachfit.tasks import get_task


def test_the_round_peg_example_inserts_with_the_defaults(mesh_examples: dict[str, str]) -> None:
    """Ø 8 mm, no chamfer, 0.1 mm per side, the taught hole off by (0.53, 0.89) mm (nine
    times the clearance across the move): the low rim leads and slides over the hole on the
    first pass and the second (1 mm to one side), and on the third (1 mm to the other) it
    dips, is centred and caught by the far wall, and turned upright into the hole."""
    setup = peg_in_hole_setup(get_task(mesh_examples["round-peg"]), seed=6, n_starts=1)
    trial = SkillTrial(setup)
    try:
        result = trial.run(None, setup.starts[0])
    finally:
        trial.robot.close()
    nodes = [v.node for v in result.visits]
    assert nodes[-5:] == ["approach_3", "contact_3", "lateral_3", "align", "insert"]
    assert result.success and result.ground_truth_inserted
