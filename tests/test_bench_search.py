from teachfit.bench.search import PAPER_TABLE1, table1


def test_table1_protocol_runs_both_methods_on_the_same_starts():
    rows = table1(seed=0, n_starts=2, n_points=40)
    assert [r.method for r in rows] == ["tshix", "ergodic"]
    for r in rows:
        assert r.ours.trials == 2
        assert 0.0 <= r.ours.low <= r.ours.rate <= r.ours.high <= 1.0
        assert r.paper == PAPER_TABLE1[r.method]
        assert r.plan_ms > 0
