"""Compiled local search of the open-tour solver (numba): 2-opt, Or-opt, Lin-Kernighan chains
and segment-swap kicks.

Why written here: the maintained packages miss one of the three things TSHIX needs. LKH-3
(``elkai``) is 20-40x over the time budget (0.7 s for 300 points); ``fast-tsp`` stops on a
wall-clock budget, so its tours change with the machine's load (the same seed must give the
same tour) and it has no iteration-count mode; OR-Tools' guided local search with a solution
limit is deterministic but was 1.05-1.24 x LKH in 25-500 ms (measured on the 300-point sets of
``benchmarks/search_speed.py``). This kernel runs a fixed, seeded number of moves: the same
input gives the same tour on every machine.

The tour is a path ``tour[0] = start, ..., tour[M-1] = dummy`` over ``M = N + 2`` nodes (node 0
the start, nodes ``1..N`` the points, node ``M-1`` a dummy at distance 0 from every node), both
ends fixed: the closed tour's edge ``(dummy, start)`` is never removed, so the path through the
points costs exactly the open tour. Moves (all in O(segment) time on arrays):

- **2-opt**: reverse ``tour[lo+1..hi]``, replacing edges ``(t_lo, t_lo+1), (t_hi, t_hi+1)`` by
  ``(t_lo, t_hi), (t_lo+1, t_hi+1)``;
- **Or-opt**: move a segment of 1-3 nodes between two neighbours elsewhere, either way round
  (done by two or three reversals);
- **Or-opt of any segment** (up to 300 points): cut the segment between a node and one of its
  candidates out (the two joined) and put it, either way round, next to a candidate of its
  first or last node nearer than the cut gains — the 3-opt "segment insertion" that no
  sequence of improving 2-opt moves reaches (it took the worst 100-point sets from 1.02 to
  <= 1.01 x LKH);
- **a new free end** (up to 300 points): cut the tour at an edge ``(u, b)``, ``u`` the new
  last point, and put the tail ``b .. z`` between two nodes before ``u``, one of them a
  candidate of ``b`` (a segment insertion across the dummy's edge, which no move above
  breaks unless the last point is a candidate);
- **Lin-Kernighan chain** (when neither improves): a sequence of up to ``depth`` 2-opt flips
  that keep ``t1`` fixed, each adding an edge from the last free end to a candidate
  neighbour, the partial gain kept positive; the chain is cut at its best closed gain. At the
  dummy (the free end of the open tour) the chain may break the longest edge of the tour.

all restricted to candidate lists (nearest and Delaunay neighbours) with don't-look bits
(a queue of nodes to look at). Then **iterated local search**: a kick swapping two adjacent
segments of any length (``A B C D -> A C B D``; whole clusters of points move; with both path
ends fixed this changes three edges, a random segment insertion, not the 4-opt double bridge
``A B C D E -> A D C B E``, which was tried and came out further from LKH-3 at the same number
of kicks, whether its segments were of any length, short or chosen along candidate edges;
up to 300 points every second kick cuts at three long edges, each the longest of three drawn),
local search from its six end nodes, kept when at most ``threshold`` longer (threshold
accepting); the shortest tour seen is returned. Distances are read from a matrix when one is
given (see ``_d`` in :mod:`teachfit.trajectories.tsp_moves`), a node's distances to its
candidates from a row computed once (``candidate_distances`` there). The functions called per
node and per kick are compiled without numba's reference counts (``leaf`` in that module), and
the per-node moves are inlined into the local search's loop (``inlined_leaf``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

# numba's on-disk cache (``cache=True``) keys each compiled function on its own file only: the
# functions of tsp_moves are compiled into this file's kernels, so an edit there alone leaves
# this file's cached kernels stale; touch this file too (or clear __pycache__) after one.
from teachfit.trajectories.tsp_moves import (
    _d,
    _lk_node,
    _move_segment,
    _or_segment,
    _reverse,
    _tail_move,
    candidate_distances,
    inlined_leaf,
    leaf,
)


@inlined_leaf
def _push(queue: np.ndarray, inq: np.ndarray, head_tail: np.ndarray, v: int) -> None:
    if not inq[v]:
        m = queue.shape[0]
        queue[head_tail[1] % m] = v
        head_tail[1] += 1
        inq[v] = True


@leaf
def _push_ends(
    queue: np.ndarray, inq: np.ndarray, head_tail: np.ndarray, tour: np.ndarray, lo: int, hi: int
) -> None:
    """Queue the nodes at both ends of the changed range ``tour[lo..hi]`` and beside it."""
    for k in (lo - 1, lo, hi, hi + 1):
        if 0 <= k < tour.shape[0]:
            _push(queue, inq, head_tail, tour[k])


# Long on purpose (> 60 lines): the innermost loop of the solver, compiled; the candidate scan,
# the two move kinds' gains and the move share a dozen locals, which a split would pass through
# calls on every candidate.
@inlined_leaf
def _improve_node(
    x: np.ndarray,
    neigh: np.ndarray,
    nd: np.ndarray,
    tour: np.ndarray,
    pos: np.ndarray,
    a: int,
    eps: float,
) -> tuple[float, int, int]:
    """Apply the first improving 2-opt or Or-opt move around node ``a``.

    Returns (gain, lo, hi): the gain (0: none found) and the index range that changed.
    """
    m = tour.shape[0]
    dummy = m - 1
    i = pos[a]
    # 2-opt, with a's successor then a's predecessor as the removed edge
    for side in range(2):
        if side == 0 and i > m - 2:
            continue
        if side == 1 and i < 1:
            continue
        b = tour[i + 1] if side == 0 else tour[i - 1]
        dab = _d(x, a, b, dummy)
        for kk in range(neigh.shape[1]):
            c, dac = neigh[a, kk], nd[a, kk]
            if dab - dac <= eps:
                break
            j = pos[c]
            if side == 0:
                if j == i + 1 or j > m - 2 or j == i:
                    continue
                cn = tour[j + 1]
                delta = dab + _d(x, c, cn, dummy) - dac - _d(x, b, cn, dummy)
                if delta > eps:
                    lo, hi = (i + 1, j) if j > i else (j + 1, i)
                    _reverse(tour, pos, lo, hi)
                    return delta, lo, hi
            else:
                if j == i - 1 or j < 1 or j == i:
                    continue
                cp = tour[j - 1]
                delta = dab + _d(x, cp, c, dummy) - dac - _d(x, b, cp, dummy)
                if delta > eps:
                    lo, hi = (j, i - 1) if j < i else (i, j - 1)
                    _reverse(tour, pos, lo, hi)
                    return delta, lo, hi
    # Or-opt: the segment of 1-3 nodes that starts at a (going forward)
    for n_seg in range(1, 4):
        s, e = i, i + n_seg - 1
        if s < 1 or e > m - 2:
            break
        p_, n_ = tour[s - 1], tour[e + 1]
        f, g = tour[s], tour[e]
        removed = _d(x, p_, f, dummy) + _d(x, g, n_, dummy) - _d(x, p_, n_, dummy)
        if removed <= eps:
            continue
        for end in range(2):
            y = f if end == 0 else g
            for kk in range(neigh.shape[1]):
                c = neigh[y, kk]
                if removed - nd[y, kk] <= eps:
                    break
                j = pos[c]
                if s <= j <= e:
                    continue
                for q in (j - 1, j):  # between (tour[q], tour[q+1]) with c at one end
                    if q < 0 or q > m - 2 or (s - 1 <= q <= e):
                        continue
                    u, v = tour[q], tour[q + 1]
                    base = _d(x, u, v, dummy)
                    for flip in (False, True):
                        first, last = (g, f) if flip else (f, g)
                        added = _d(x, u, first, dummy) + _d(x, last, v, dummy) - base
                        delta = removed - added
                        if delta > eps:
                            lo, hi = _move_segment(tour, pos, s, e, q, flip)
                            return delta, lo, hi
    return 0.0, 0, -1


@leaf
def _local_search(
    x: np.ndarray,
    neigh: np.ndarray,
    nd: np.ndarray,
    tour: np.ndarray,
    pos: np.ndarray,
    seeds: np.ndarray,
    eps: float,
    queue: np.ndarray,
    inq: np.ndarray,
    head_tail: np.ndarray,
    flips: np.ndarray,
    breadth: int,
    segments: bool,
) -> float:
    """Local search from the nodes ``seeds`` until no move improves (2-opt and Or-opt of 1-3
    nodes, then with ``segments`` a new free end and Or-opt of any segment, then
    Lin-Kernighan chains when ``flips`` has rows); returns the total gain."""
    head_tail[:] = 0
    inq[:] = False
    for v in seeds:
        _push(queue, inq, head_tail, v)
    dummy = tour.shape[0] - 1
    gain = 0.0
    while head_tail[0] < head_tail[1]:
        a = queue[head_tail[0] % queue.shape[0]]
        head_tail[0] += 1
        inq[a] = False
        if a == dummy:
            continue
        delta, lo, hi = _improve_node(x, neigh, nd, tour, pos, a, eps)
        if delta <= 0.0 and segments:
            delta, lo, hi = _tail_move(x, neigh, nd, tour, pos, a, eps)
            if delta <= 0.0:
                delta, lo, hi = _or_segment(x, neigh, nd, tour, pos, a, eps)
        if delta > 0.0:
            gain += delta
            _push_ends(queue, inq, head_tail, tour, lo, hi)
            _push(queue, inq, head_tail, a)
            continue
        if flips.shape[0] == 0:
            continue
        delta, n_flips = _lk_node(x, neigh, nd, tour, pos, a, eps, flips, breadth)
        if delta > 0.0:
            gain += delta
            for r in range(n_flips):
                _push_ends(queue, inq, head_tail, tour, flips[r, 0], flips[r, 1])
            _push(queue, inq, head_tail, a)
    return gain


@leaf
def _long_edge_cuts(
    x: np.ndarray, tour: np.ndarray, draw: np.ndarray, samples: int
) -> tuple[int, int, int]:
    """Cuts of a kick at long edges: three tour edges, each the longest of ``samples`` drawn
    (xorshift seeded by the kick's ``draw``); returns ``(a, lb, lc)`` as
    :func:`_kick_cuts`."""
    m = tour.shape[0]
    h = np.uint64(draw[0] * 1000003 + draw[1] * 7919 + draw[2])
    lo, hi, total = m, 0, 0  # the three cuts' least, largest and sum (no array: a leaf)
    for _ in range(3):
        best_c, best_len = 1, -1.0
        for _ in range(samples):
            h ^= h << np.uint64(13)
            h ^= h >> np.uint64(7)
            h ^= h << np.uint64(17)
            c = 1 + int(h % np.uint64(m - 1))  # the edge (tour[c-1], tour[c]), 1 <= c < m
            length = _d(x, tour[c - 1], tour[c], m - 1)
            if length > best_len:
                best_c, best_len = c, length
        lo, hi, total = min(lo, best_c), max(hi, best_c), total + best_c
    mid = total - lo - hi
    if lo == mid or mid == hi:
        return 0, 0, 0
    return lo, mid - lo, hi - mid


@leaf
def _kick_cuts(
    x: np.ndarray, tour: np.ndarray, draws: np.ndarray, r: int, window: int, long_cuts: int
) -> tuple[int, int, int]:
    """The segments of kick ``r``: ``B = tour[a..a+lb-1]`` and the ``lc`` nodes after it
    (``lb = 0``: no kick). Random lengths up to ``window``; with ``long_cuts`` every second
    kick cuts at long edges instead (:func:`_long_edge_cuts`)."""
    inner = tour.shape[0] - 2  # movable positions 1..m-2
    if long_cuts > 0 and r % 2 == 0:
        return _long_edge_cuts(x, tour, draws[r], long_cuts)
    lb = 1 + draws[r, 1] % (window - 1) if window > 1 else 1
    lc = 1 + draws[r, 2] % max(1, window - lb)
    if lb + lc > inner:
        return 0, 0, 0
    return 1 + draws[r, 0] % (inner - lb - lc + 1), lb, lc


@leaf
def _kick(
    x: np.ndarray, tour: np.ndarray, pos: np.ndarray, a: int, lb: int, lc: int, ends: np.ndarray
) -> float:
    """Swap ``B = tour[a..a+lb-1]`` and the ``lc`` nodes after it (``A B C D -> A C B D``);
    the six nodes at the changed edges go to ``ends``. Returns the gain (negative: longer)."""
    dummy = tour.shape[0] - 1
    b_end, c_end = a + lb - 1, a + lb + lc - 1
    pa, na = tour[a - 1], tour[c_end + 1]
    b0, b1, c0, c1 = tour[a], tour[b_end], tour[b_end + 1], tour[c_end]
    delta = (
        _d(x, pa, b0, dummy)
        + _d(x, b1, c0, dummy)
        + _d(x, c1, na, dummy)
        - _d(x, pa, c0, dummy)
        - _d(x, c1, b0, dummy)
        - _d(x, b1, na, dummy)
    )
    _move_segment(tour, pos, a, b_end, c_end, True)  # A B C D -> A C rev(B) D
    _reverse(tour, pos, c_end - lb + 1, c_end)  # -> A C B D
    ends[0], ends[1], ends[2], ends[3], ends[4], ends[5] = pa, na, b0, b1, c0, c1
    return delta


# Long on purpose (> 60 lines by its numpydoc docstring): the iterated local search's whole
# loop in one compiled function (kick, local search from the kick's ends, acceptance, best tour
# kept), so that its buffers are allocated once and nothing crosses into Python per kick.
@njit(cache=True)
def improve_tour(
    x: np.ndarray,
    neigh: np.ndarray,
    tour: np.ndarray,
    draws: np.ndarray,
    window: int,
    eps: float,
    threshold: float = 0.0,
    depth: int = 6,
    breadth: int = 3,
    segments: bool = True,
    long_cuts: int = 0,
) -> np.ndarray:
    """Local search, then one kick per row of ``draws`` (three non-negative ints each).

    A kicked tour is kept when it is at most ``threshold`` longer than before (threshold
    accepting); the shortest tour seen is returned.

    Parameters
    ----------
    x : ndarray, shape (M - 1, D)
        Weighted coordinates of the start (row 0) and the points, or their distance matrix
        with the dummy's zero row and column, shape (M, M) (see ``_d`` in ``tsp_moves``).
    neigh : ndarray of int, shape (M - 1, K)
        K nearest other nodes of each node, nearest first.
    tour : ndarray of int, shape (M,)
        Initial path: ``tour[0] = 0``, ``tour[M-1] = M-1`` (the dummy).
    segments : bool
        Also the moves of a new free end and Or-opt of any segment.
    long_cuts : int
        With > 0, every second kick cuts at the longest of this many drawn edges.
    """
    m = tour.shape[0]
    tour = tour.copy()
    pos = np.empty(m, dtype=np.int64)
    for k in range(m):
        pos[tour[k]] = k
    queue = np.empty(m, dtype=np.int64)
    inq = np.zeros(m, dtype=np.bool_)
    head_tail = np.zeros(2, dtype=np.int64)
    flips = np.zeros((depth, 2), dtype=np.int64)
    all_nodes = np.arange(m - 1)
    nd = candidate_distances(x, neigh)
    _local_search(
        x, neigh, nd, tour, pos, all_nodes, eps, queue, inq, head_tail, flips, breadth, segments
    )
    if m - 2 < 4:
        return tour
    window = min(window, m - 3)
    saved_tour = tour.copy()
    saved_pos = pos.copy()
    ends = np.empty(6, dtype=np.int64)
    best_tour = tour.copy()
    total, best = 0.0, 0.0  # gain of the current / best tour over the first local optimum
    for r in range(draws.shape[0]):
        a, lb, lc = _kick_cuts(x, tour, draws, r, window, long_cuts)
        if lb == 0:
            continue
        saved_tour[:] = tour
        saved_pos[:] = pos
        gain = _kick(x, tour, pos, a, lb, lc, ends)
        gain += _local_search(
            x, neigh, nd, tour, pos, ends, eps, queue, inq, head_tail, flips, breadth, segments
        )
        if gain <= eps - threshold:  # longer than accepted: undo
            tour[:] = saved_tour
            pos[:] = saved_pos
            continue
        total += gain
        if total > best + eps:
            best = total
            best_tour[:] = tour
    return best_tour
