"""Variant grid of the planning benchmark (the sweep itself runs in `bench planning --variants`)."""

import pytest

from teachfit.bench.planning_variants import VariantResult, sample_variants, variant_rows
from teachfit.core.errors import PlanningError
from teachfit.plans import PARTS, build_assembly


@pytest.mark.parametrize("task", ["l-groove", "tenon"])
def test_variants_span_the_grid_and_build(task):
    variants = sample_variants(task, 4, seed=0)
    assert variants == sample_variants(task, 4, seed=0)  # seeded
    default = PARTS[task]()
    assert variants[0]["clearance"] == pytest.approx(0.0005)
    for over in variants:
        assert 0.0005 <= over["clearance"] <= default.clearance
        scale = over["base_length" if task == "l-groove" else "bar_side"] / (
            default.base_length if task == "l-groove" else default.bar_side
        )
        assert 0.9 - 1e-12 <= scale <= 1.1 + 1e-12
        build_assembly(task, **over)  # every sampled variant is a valid part
    with pytest.raises(PlanningError):
        sample_variants(task, 0)


def test_variant_rows_report_errors_in_place():
    rows = variant_rows(
        [
            VariantResult("tenon", 0.0005, 1.0, 3, 1.0, 0.02, 1, 2, 0),
            VariantResult("tenon", 0.0005, 0.9, 0, 0.0, 0.0, 0, 0, 0, "start collides"),
        ]
    )
    assert rows[0][:5] == ["tenon", "0.50", "x1.000", "3", "100 %"]
    assert "start collides" in rows[1][4]
