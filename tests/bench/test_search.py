import numpy as np
import pytest

from teachfit.bench.search import (
    PAPER_ABLATION,
    PAPER_TABLE1,
    PAPER_TABLE2,
    PAPER_TABLE3,
    TABLE1_METHODS,
    TABLE3_METHODS,
    chosen_methods,
    table1,
    table2,
    table3,
)
from teachfit.bench.search_jobs import run_jobs
from teachfit.core.errors import TeachfitError

# seed 1: the teacher's recording of peg2d that the CLI and execution tests make too (cached)
SEED = 1


def test_table1_protocol_runs_every_method_on_the_same_starts():
    rows = table1(seed=SEED, n_starts=1, n_points=20, workers=0)
    assert [r.method for r in rows] == ["tshix", "tshix-iid", "ergodic"]
    for r in rows:
        assert r.ours.trials == 1
        assert 0.0 <= r.ours.low <= r.ours.rate <= r.ours.high <= 1.0
        assert r.paper == PAPER_TABLE1[r.method.split("-")[0]]
        assert r.length > 0 and np.isfinite(r.ergodic)  # plan_ms: a benchmark figure
    # the ergodic trajectory is planned as long as the mean TSHIX pass (x-y, 2D: same metric)
    assert abs(rows[2].length - rows[0].length) < 0.1 * rows[0].length


def test_table2_and_ablation_rows_line_up_with_the_paper():
    rows, abl = table2(seed=SEED, sizes=(20, 40), n_traj=1, ablation=(20,), workers=0)
    assert [r.method for r in rows] == ["N=20", "N=40"]
    assert [r.method for r in abl] == ["N=20 no-ff"]
    assert all(r.ours.trials == 1 for r in rows + abl)
    assert rows[1].length > rows[0].length  # more samples, longer tour
    # each row stands beside the paper's figure for its N (none for these small N)
    assert [r.paper for r in rows] == [PAPER_TABLE2.get(20), PAPER_TABLE2.get(40)]
    assert abl[0].paper == PAPER_ABLATION.get(20)
    # the transcribed paper: without feed-forward fewer successes at every N, same trials
    for n, (ok, trials) in PAPER_ABLATION.items():
        assert ok < PAPER_TABLE2[n][0] and trials == PAPER_TABLE2[n][1], n


def test_table3_rows_and_their_order_on_socket3d():
    assert TABLE3_METHODS == (
        "random-walk",
        "spiral",
        "tshix-1demo",
        "tshix-2demo",
        "tshix-2demo-diag",
        "tshix-2demo-auto",
        "ergodic-3d-2demo",
    )
    # every row but the spiral (its length is set by the distribution's radius, not by N: a
    # 98 s execution here); the rows in table order whatever order they were asked in
    asked = [
        "ergodic-3d-2demo",
        "random-walk",
        "tshix-1demo",
        "tshix-2demo",
        "tshix-2demo-diag",
        "tshix-2demo-auto",
    ]
    # seed 2: three of the TSHIX rows insert, the other executions run to their end
    rows = table3(seed=2, n_starts=1, n_points=8, workers=0, methods=asked)
    assert [r.method for r in rows] == [m for m in TABLE3_METHODS if m != "spiral"]
    assert rows[0].paper == PAPER_TABLE3["random-walk"] and rows[-1].paper is None
    assert all(r.ours.trials == 1 for r in rows)
    # the random walk and the ergodic trajectory are sized by the 2-demo TSHIX plan
    tshix2 = rows[3]
    assert abs(rows[0].length - tshix2.length) < 0.1 * tshix2.length


def test_a_table_refuses_a_method_it_has_not():
    with pytest.raises(TeachfitError, match="Table III has no method 'tshix'; available: random"):
        chosen_methods(["tshix"], TABLE3_METHODS, "III")
    assert chosen_methods(["ergodic", "tshix"], TABLE1_METHODS, "I") == ("tshix", "ergodic")


def test_parallel_jobs_match_inline_jobs():
    from teachfit.bench.search import _jobs, _peg_setup
    from teachfit.tasks.registry import get_task

    overrides, demo, model = _peg_setup(SEED, 0.0005)
    task = get_task("peg2d", **overrides)
    starts = task.protocol.protocol_starts("table1", 2, np.random.default_rng(3))
    jobs = _jobs("peg2d", overrides, model, starts, "tshix", 5, [3, 5])  # one inserts, one not
    inline = run_jobs(jobs, workers=0)
    pooled = run_jobs(jobs, workers=2)
    assert [r.success for r in inline] == [r.success for r in pooled]
    assert np.allclose([r.path_length for r in inline], [r.path_length for r in pooled])


def test_a_job_reads_the_same_noise_whatever_its_worker_ran_before():
    """A worker's robot restarts its noise from each job's seed: a job's draws do not depend
    on which jobs the pool handed that worker first."""
    from teachfit.bench import search_jobs
    from teachfit.bench.search import _jobs, _peg_setup
    from teachfit.tasks.registry import get_task

    overrides, _, model = _peg_setup(SEED, 0.0005)
    task = get_task("peg2d", **overrides)
    starts = [task.contact_pose([0.001, 0.0]), task.contact_pose([0.0, 0.001])]
    jobs = _jobs("peg2d", overrides, model, starts, "tshix", 10, [7, 8])
    robot = search_jobs._robot("peg2d", jobs[0].overrides, 0, jobs[0].robot)
    alone = run_jobs(jobs[1:], workers=0)[0]
    drawn_alone = robot.rng.bit_generator.state
    after = run_jobs(jobs, workers=0)[1]
    assert robot.rng.bit_generator.state == drawn_alone  # the same draws, none left over
    assert (alone.success, alone.reason) == (after.success, after.reason)
