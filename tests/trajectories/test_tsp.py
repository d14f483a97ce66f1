import itertools

import numpy as np
import pytest

from teachfit.core.errors import PlanningError
from teachfit.trajectories.tsp import open_tour, path_length


def _brute(start, pts):
    best = None
    for perm in itertools.permutations(range(len(pts))):
        L = path_length(start, pts, np.array(perm))
        if best is None or L < best[0]:
            best = (L, perm)
    return best


@pytest.mark.parametrize("seed", range(4))
def test_small_instances_are_optimal(seed):
    rng = np.random.default_rng(seed)
    pts = rng.uniform(-1, 1, size=(7, 2))
    start = rng.uniform(-1, 1, size=2)
    L, _ = _brute(start, pts)
    for solver in ("fast", "lkh"):
        r = open_tour(pts, start, solver=solver)
        assert r.length == pytest.approx(L, rel=1e-9)


def test_open_end_is_free_and_start_fixed():
    # points on a line to the right of the start: the optimal open path just walks outwards,
    # a closed tour would have to come back (twice the length)
    pts = np.column_stack([np.linspace(1, 10, 10), np.zeros(10)])[::-1].copy()
    r = open_tour(pts)
    assert r.length == pytest.approx(10.0)
    np.testing.assert_array_equal(pts[r.order][:, 0], np.arange(1, 11))
    # start in the middle of a line: go to the nearer end first, then sweep
    r = open_tour(pts, start=np.array([4.0, 0.0]))
    assert r.length == pytest.approx(3.0 + 9.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_close_to_lkh_on_gaussian_samples(dim):
    rng = np.random.default_rng(10 + dim)
    pts = rng.normal(size=(300, dim)) * np.array([1.0, 0.5, 0.3][:dim])
    r = open_tour(pts, rng=np.random.default_rng(0))
    assert sorted(r.order.tolist()) == list(range(300))
    ref = open_tour(pts, solver="lkh")
    assert r.length <= 1.015 * ref.length  # single instances; the <= 1.01 goal is a median
    # the solver's speed is a benchmark figure (benchmarks/search_speed.py), not a test


def test_weights_change_the_metric():
    pts = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 10.0], [0.0, 2.0, 0.0]])
    heavy = open_tour(pts, weights=np.array([1.0, 1.0, 1.0]))
    light = open_tour(pts, weights=np.array([1.0, 1.0, 0.01]))
    assert heavy.order[-1] == 1  # rotation far away: visit last
    assert light.order[0] == 1  # rotation cheap: visit first
    assert light.length == pytest.approx(path_length(np.zeros(3), pts, light.order, [1, 1, 0.01]))


def test_seeded_and_bad_input():
    pts = np.random.default_rng(0).normal(size=(60, 2))
    a = open_tour(pts, rng=np.random.default_rng(3))
    b = open_tour(pts, rng=np.random.default_rng(3))
    np.testing.assert_array_equal(a.order, b.order)
    assert open_tour(pts[:1]).order.tolist() == [0]
    for bad in (np.zeros((0, 2)), np.array([[np.nan, 0.0]])):
        with pytest.raises(PlanningError):
            open_tour(bad)
    with pytest.raises(PlanningError):
        open_tour(pts, solver="ga")


def test_clustered_points_close_to_lkh():
    # 8 tight clusters: the order of the clusters is the hard part (Delaunay candidates and
    # double bridges of any length); the tour is the same on every call
    rng = np.random.default_rng(5)
    centres = rng.uniform(-0.02, 0.02, (8, 2))
    pts = centres[rng.integers(0, 8, 200)] + rng.normal(0.0, 0.002, (200, 2))
    a, b = open_tour(pts), open_tour(pts)
    np.testing.assert_array_equal(a.order, b.order)
    assert sorted(a.order.tolist()) == list(range(200))
    assert a.length <= 1.025 * open_tour(pts, solver="lkh").length  # 1.018 measured


def test_duplicate_points_fall_back_and_stay_valid():
    # repeated points make qhull's triangulation degenerate; 1-D points have none at all
    base = np.random.default_rng(1).uniform(size=(20, 2))
    pts = np.vstack([base, base, base[:5]])
    r = open_tour(pts)
    assert sorted(r.order.tolist()) == list(range(len(pts)))
    assert r.length == pytest.approx(open_tour(base).length, rel=0.05)
    line = np.random.default_rng(2).uniform(0, 1, (30, 1))
    assert open_tour(line).length == pytest.approx(line.max())  # sweep out from 0


def test_lin_kernighan_chains_keep_a_valid_near_optimal_tour(monkeypatch):
    # the chains run above tsp._LK_FROM points; lowered here to keep the instance small
    import teachfit.trajectories.tsp as tsp

    monkeypatch.setattr(tsp, "_LK_FROM", 50)
    pts = np.random.default_rng(7).uniform(-1, 1, size=(150, 3))
    a, b = open_tour(pts), open_tour(pts)
    np.testing.assert_array_equal(a.order, b.order)
    assert sorted(a.order.tolist()) == list(range(150))
    assert a.length == pytest.approx(path_length(np.zeros(3), pts, a.order))
    assert a.length <= 1.02 * open_tour(pts, solver="lkh").length


#: LKH-3 (elkai, RUNS=1) open-tour lengths of the instances of ``benchmarks/search_speed.py
#: --part tsp`` (``_points(family, n, default_rng((0, i, n)))``) on which the solver was
#: furthest from LKH before Or-opt of any segment (1.0255 and 1.0187) and before the new-end
#: move and the long-edge kicks (1.0134)
_LKH = {
    ("gaussian", 300, 7): 0.5780632135642297,
    ("gaussian", 100, 2): 0.305350695024383,
    ("gaussian", 300, 0): 0.546371295507994,
}


@pytest.mark.parametrize("key", list(_LKH))
def test_formerly_worst_instances_are_within_1_percent_of_lkh(key):
    family, n, i = key
    assert family == "gaussian"
    pts = np.random.default_rng((0, i, n)).normal(0.0, 0.01, (n, 2))  # _points("gaussian", ...)
    r = open_tour(pts)
    assert sorted(r.order.tolist()) == list(range(n))
    assert r.length <= 1.01 * _LKH[key]


def test_distance_matrix_gives_the_tour_of_the_coordinates(monkeypatch):
    # up to tsp._MATRIX_UP_TO nodes the kernel reads distances from a matrix (faster); it must
    # find the same tour as from the coordinates, and a valid one
    import teachfit.trajectories.tsp as tsp

    pts = np.random.default_rng(4).normal(0.0, 0.01, (120, 2))
    assert tsp._distances(np.vstack([np.zeros(2), pts])).shape == (122, 122)
    with_matrix = open_tour(pts)
    monkeypatch.setattr(tsp, "_MATRIX_UP_TO", 0)
    assert tsp._distances(np.vstack([np.zeros(2), pts])).shape == (121, 2)
    with_coords = open_tour(pts)
    np.testing.assert_array_equal(with_matrix.order, with_coords.order)
    assert sorted(with_matrix.order.tolist()) == list(range(120))
    assert with_matrix.length == pytest.approx(path_length(np.zeros(2), pts, with_matrix.order))


def test_more_kicks_never_give_a_longer_tour():
    # each run's default 5 N kicks at 300 points begin with any fewer ones (the same seeded
    # draws) and the shortest tour seen is kept: no instance may come out longer
    pts = np.random.default_rng((0, 1, 300)).normal(0.0, 0.01, (300, 2))
    fewer = open_tour(pts, n_kicks=1000)
    default = open_tour(pts)
    assert default.length <= fewer.length
    assert sorted(default.order.tolist()) == list(range(300))


def test_a_second_run_keeps_the_shorter_tour(monkeypatch):
    # up to 300 points two runs of the local search, the first the single run of before (the
    # caller's kicks): the tour is never longer than that run's, and shorter on some sets
    import teachfit.trajectories.tsp as tsp

    shorter = 0
    for i in range(4):
        pts = np.random.default_rng((8, i, 300)).normal(0.0, 0.01, (300, 2))
        both = open_tour(pts, rng=np.random.default_rng(5))
        monkeypatch.setattr(tsp, "_RUNS", 1)
        first = open_tour(pts, rng=np.random.default_rng(5))
        monkeypatch.setattr(tsp, "_RUNS", 2)
        assert both.length <= first.length
        shorter += both.length < first.length * (1 - 1e-9)
    assert shorter >= 1


def _path(x, tour):
    # the length of tour[0..M-2] (the dummy, tour[M-1], is at distance 0)
    return float(np.linalg.norm(np.diff(x[tour[:-1]], axis=0), axis=1).sum())


def test_new_end_move_keeps_a_path_and_gains_what_it_says():
    # the tail move on scrambled tours: a valid path (start and dummy fixed, pos in step), its
    # gain the length it saves
    from teachfit.trajectories.tsp_moves import _tail_move, candidate_distances

    rng = np.random.default_rng(3)
    x = rng.uniform(size=(40, 2))  # node 0 the start, 40 = the dummy
    neigh = np.argsort(np.linalg.norm(x[:, None] - x[None], axis=2), axis=1)[:, 1:9]
    nd = candidate_distances(x, neigh)
    applied = 0
    for _ in range(20):
        tour = np.concatenate([[0], 1 + rng.permutation(39), [40]]).astype(np.int64)
        pos = np.argsort(tour)
        for a in range(1, 40):
            before = _path(x, tour)
            gain, lo, hi = _tail_move(x, neigh, nd, tour, pos, a, 1e-12)
            if gain > 0:
                applied += 1
                assert gain == pytest.approx(before - _path(x, tour))
                assert tour[0] == 0 and tour[-1] == 40 and sorted(tour) == list(range(41))
                np.testing.assert_array_equal(pos[tour], np.arange(41))
                assert 0 < lo <= hi < 40
    assert applied > 20


def test_long_edge_kicks_cut_inside_the_path():
    from teachfit.trajectories.tsp_kernel import _kick_cuts

    rng = np.random.default_rng(5)
    x = rng.uniform(size=(30, 2))
    tour = np.concatenate([[0], 1 + rng.permutation(29), [30]]).astype(np.int64)
    draws = rng.integers(0, 1 << 30, size=(200, 3), dtype=np.int64)
    for r in range(200):
        a, lb, lc = _kick_cuts(x, tour, draws, r, 1 << 30, 3)
        if lb:
            assert a >= 1 and lc >= 1 and a + lb + lc - 1 <= 29  # B and C among the points


def test_candidate_distances_are_the_kernels_distances_in_both_modes():
    # the kernel's candidate scans read these instead of the matrix or the coordinates: the
    # same values in both modes, so the same tours
    from scipy.spatial.distance import cdist

    from teachfit.trajectories.tsp import _candidates, _distances
    from teachfit.trajectories.tsp_moves import candidate_distances

    x = np.random.default_rng(5).uniform(size=(31, 2))
    neigh = _candidates(x, 6)
    exact = np.take_along_axis(cdist(x, x), neigh, axis=1)
    np.testing.assert_array_equal(candidate_distances(_distances(x), neigh), exact)
    np.testing.assert_allclose(candidate_distances(np.ascontiguousarray(x), neigh), exact)
