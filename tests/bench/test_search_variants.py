import json

from teachfit.bench.search_variants import figure_data, goal_misses, results_json, run_variant
from teachfit.tasks.variants import Variant, variant
from teachfit.viz.variant_figures import success_by_parameter


def test_one_variant_runs_tshix_and_ergodic_on_the_same_starts(tmp_path):
    # the default cell as a variant: its teacher demonstration is the session-cached one
    v = Variant("peg2d", (("peg_diameter_mm", 20.0), ("friction", 0.3)), ())
    ticks = []
    res = run_variant(
        v, seed=0, n_starts=1, n_points=40, workers=0, progress=lambda: ticks.append(1)
    )
    assert res.kept == 1 and res.tried >= 1 and not res.why
    assert [r.method for r in res.rows] == ["tshix", "ergodic"]
    assert all(r.ours.trials == 1 for r in res.rows) and len(ticks) == 2
    missed = goal_misses([res])
    assert (res.rate("tshix") < 0.9) == bool(missed)
    data = figure_data([res])
    assert data[0]["values"] == {"peg_diameter_mm": 20.0, "friction": 0.3}
    fig = success_by_parameter(data, "test", goal=0.9)
    assert len(fig.axes) == 2 and fig.axes[0].get_legend() is not None


def test_without_ergodic_only_the_tshix_row_is_run():
    v = variant("peg2d", peg_diameter_mm=20.0, clearance_mm=0.5, friction=0.3, chamfers=1.0)
    ticks = []
    res = run_variant(v, 0, 1, 8, 0, lambda: ticks.append(1), ergodic=False)  # a short tour
    assert [r.method for r in res.rows] == ["tshix"] and len(ticks) == 1
    assert res.rows[0].ours.trials == 1
    doc = json.loads(results_json([res]))  # what the CLI saves after each variant
    assert doc[0]["variant"] == "d20 c0.5 mu0.3 chamfered" and doc[0]["demos_kept"] == 1
    assert doc[0]["rates"]["tshix"]["trials"] == 1 and "ergodic" not in doc[0]["rates"]


def test_passes_go_on_through_fresh_samples_from_the_same_first_tour():
    v = variant("peg2d", peg_diameter_mm=20.0, clearance_mm=0.5, friction=0.3, chamfers=1.0)
    one, two = (run_variant(v, 0, 1, 6, 0, None, ergodic=False, passes=k) for k in (1, 2))
    # the second pass appends a tour of fresh samples: the planned path grows
    assert two.rows[0].length > one.rows[0].length > 0
