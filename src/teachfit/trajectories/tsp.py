"""Shortest open tour from a fixed start through N points (fixed start, free end).

The open path is solved as a closed tour over ``start, points…, dummy`` in which the dummy is at
zero distance from every node and the edge ``(dummy, start)`` may never be removed: the closed
tour ``start → p_1 → … → p_N → dummy → start`` then costs exactly the open path.

``solver="fast"`` (default) is written here because no maintained Python package offers a
millisecond open-path heuristic of LKH-like quality: nearest-neighbour construction, then local
search with 2-opt and Or-opt moves restricted to K nearest neighbours (``scipy.spatial.cKDTree``)
with don't-look bits, then iterated local search with local double-bridge kicks (accepted when
they shorten the tour). Scalar moves use Python lists: for a few hundred nodes this is faster than
numpy calls on tiny arrays. ``solver="lkh"`` calls LKH-3 through ``elkai`` (slow, reference
quality).

Distances are Euclidean after scaling each coordinate by ``weights`` (e.g. ``(1, 1, ℓ)`` to
count a rotation about z as ℓ metres per radian).
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.distance import cdist

from teachfit.core.errors import PlanningError


@dataclass(frozen=True)
class OpenTour:
    """Result of an open-tour search.

    Attributes
    ----------
    order : ndarray of int, shape (N,)
        Indices into ``points`` in visiting order (the start is not included).
    length : float
        Weighted length of ``start → points[order[0]] → … → points[order[-1]]``.
    """

    order: np.ndarray
    length: float


def path_length(start: np.ndarray, points: np.ndarray, order: np.ndarray, weights=None) -> float:
    """Weighted length of the open path ``start, points[order]`` (weights scale coordinates)."""
    w = 1.0 if weights is None else np.asarray(weights, dtype=float)
    path = np.vstack([np.asarray(start, float)[None], np.asarray(points, float)[order]]) * w
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


class _LocalSearch:
    """2-opt + Or-opt on a cyclic tour held in lists, with neighbour lists and don't-look bits."""

    def __init__(
        self,
        dist: list[list[float]],
        neigh: list[list[int]],
        tour: list[int],
        start: int,
        dummy: int,
        eps: float,
    ) -> None:
        self.d, self.neigh, self.tour = dist, neigh, tour
        self.n = len(tour)
        self.pos = [0] * self.n
        for i, v in enumerate(tour):
            self.pos[v] = i
        self.start, self.dummy, self.eps = start, dummy, eps
        self.gain = 0.0  # total length removed by improving moves so far

    def _fixed(self, u: int, v: int) -> bool:
        return (u == self.start and v == self.dummy) or (u == self.dummy and v == self.start)

    def _reverse(self, i: int, j: int) -> None:
        """Reverse the cyclic segment tour[i..j] (forward), or its complement if shorter."""
        n, tour, pos = self.n, self.tour, self.pos
        length = (j - i) % n + 1
        if 2 * length > n:
            i, j, length = (j + 1) % n, (i - 1) % n, n - length
        for k in range(length // 2):
            ii, jj = (i + k) % n, (j - k) % n
            u, v = tour[ii], tour[jj]
            tour[ii], tour[jj] = v, u
            pos[v], pos[u] = ii, jj

    def two_opt(self, a: int) -> list[int] | None:
        d, tour, pos, n = self.d, self.tour, self.pos, self.n
        da = d[a]
        for succ in (True, False):
            i = pos[a]
            b = tour[(i + 1) % n] if succ else tour[i - 1]
            if self._fixed(a, b):
                continue
            dab = da[b]
            for c in self.neigh[a]:
                dac = da[c]
                if dac >= dab:
                    break
                j = pos[c]
                e = tour[(j + 1) % n] if succ else tour[j - 1]
                if c == b or e == a or self._fixed(c, e):
                    continue
                delta = dab + d[c][e] - dac - d[b][e]
                if delta > self.eps:
                    self.gain += delta
                    if succ:
                        self._reverse(pos[b], pos[c])
                    else:
                        self._reverse(pos[a], pos[e])
                    return [a, b, c, e]
        return None

    def or_opt(self, a: int) -> list[int] | None:
        d, tour, pos, n = self.d, self.tour, self.pos, self.n
        start, dummy, eps = self.start, self.dummy, self.eps
        i = pos[a]
        rot = tour[i:] + tour[:i]  # rot[0] = a
        p = rot[-1]
        for seg_len in (1, 2, 3):
            if n < seg_len + 3:
                break
            seg = rot[:seg_len]
            s1, s2, nx = seg[0], seg[-1], rot[seg_len]
            if s2 == start or s2 == dummy:
                break
            gain_rm = d[p][s1] + d[s2][nx] - d[p][nx]
            if gain_rm <= eps:
                continue
            best = None
            for end, other in ((s1, s2), (s2, s1)):
                dend, doth = d[end], d[other]
                for c in self.neigh[end]:
                    dce = dend[c]
                    if dce >= gain_rm:
                        break
                    if c in seg:
                        continue
                    j = pos[c]
                    dc = d[c]
                    for left in (True, False):  # insert between (c, succ c) or (pred c, c)
                        o = tour[(j + 1) % n] if left else tour[j - 1]
                        if o in seg or (c == start and o == dummy) or (c == dummy and o == start):
                            continue
                        delta = gain_rm - (dce + doth[o] - dc[o])
                        if delta > eps and (best is None or delta > best[0]):
                            # nodes in tour order: x, [first … last], y
                            best = (delta, c, o, end) if left else (delta, o, c, other)
            if best is not None:
                delta, x, y, first = best
                self.gain += delta
                oriented = seg if first == s1 else seg[::-1]
                rest = rot[seg_len:]
                ix = rest.index(x)
                if rest[(ix + 1) % len(rest)] != y:  # (x, y) adjacent in reverse order
                    oriented = oriented[::-1]
                    ix = rest.index(y)
                new = rest[: ix + 1] + oriented + rest[ix + 1 :]
                tour[:] = new
                for k, v in enumerate(new):
                    pos[v] = k
                return [p, nx, s1, s2, x, y]
        return None

    def run(self, nodes: list[int]) -> None:
        queue = deque(nodes)
        queued = [False] * self.n
        for v in nodes:
            queued[v] = True
        while queue:
            a = queue.popleft()
            queued[a] = False
            if a == self.dummy:
                continue
            touched = self.two_opt(a) or self.or_opt(a)
            if touched:
                for v in touched + [a]:
                    if not queued[v]:
                        queued[v] = True
                        queue.append(v)


def _nearest_neighbour(x: np.ndarray) -> list[int]:
    """Greedy path from node 0 always to the nearest unvisited node."""
    n = x.shape[0]
    left = np.ones(n, dtype=bool)
    left[0] = False
    order, cur = [0], 0
    for _ in range(n - 1):
        dd = np.einsum("ij,ij->i", x - x[cur], x - x[cur])
        dd[~left] = np.inf
        cur = int(np.argmin(dd))
        left[cur] = False
        order.append(cur)
    return order


def _fast(
    x: np.ndarray,
    rng: np.random.Generator,
    n_neighbours: int,
    n_kicks: int,
    time_limit: float | None,
) -> list[int]:
    n = x.shape[0]  # node 0 = start, 1..n-1 = points; dummy = n
    t0 = time.perf_counter()
    full = np.zeros((n + 1, n + 1))
    full[:n, :n] = cdist(x, x)
    dist = full.tolist()
    k = min(n_neighbours, n - 1)
    _, idx = cKDTree(x).query(x, k=k + 1)
    neigh = [[int(j) for j in row if j != i] for i, row in enumerate(np.atleast_2d(idx))]
    neigh.append([])
    tour = _nearest_neighbour(x) + [n]
    scale = float(full.max()) or 1.0
    ls = _LocalSearch(dist, neigh, tour, 0, n, 1e-12 * scale)
    ls.run(list(range(n)))
    if n < 8:
        return ls.tour
    size = n + 1  # nodes in the cyclic tour
    window = min(n - 1, 50)
    draws = rng.integers(0, 1 << 30, size=(n_kicks, 3))
    tour, pos = ls.tour, ls.pos
    for kick in range(n_kicks):
        if time_limit is not None and time.perf_counter() - t0 > time_limit:
            break
        # local double bridge on the cycle: A B C D -> A C B D with B, C inside a window
        a = int(draws[kick, 0] % size)
        lb = 1 + int(draws[kick, 1] % (window - 1))
        lc = 1 + int(draws[kick, 2] % (window - lb))
        seg = [tour[(a + q) % size] for q in range(lb + lc)]
        pa, na = tour[a - 1], tour[(a + lb + lc) % size]
        if ls._fixed(pa, seg[0]) or ls._fixed(seg[lb - 1], seg[lb]) or ls._fixed(seg[-1], na):
            continue
        delta = (
            dist[pa][seg[0]]
            + dist[seg[lb - 1]][seg[lb]]
            + dist[seg[-1]][na]
            - dist[pa][seg[lb]]
            - dist[seg[-1]][seg[0]]
            - dist[seg[lb - 1]][na]
        )
        saved_tour, saved_pos, saved_gain = tour[:], pos[:], ls.gain
        new = seg[lb:] + seg[:lb]
        for q, v in enumerate(new):
            tour[(a + q) % size] = v
            pos[v] = (a + q) % size
        ls.gain += delta
        ls.run([pa, na, seg[0], seg[lb - 1], seg[lb], seg[-1]])
        if ls.gain <= saved_gain + ls.eps:  # not shorter: undo
            tour[:] = saved_tour
            pos[:] = saved_pos
            ls.gain = saved_gain
    return ls.tour


def _lkh(x: np.ndarray, runs: int) -> list[int]:
    import elkai  # optional reference solver

    n = x.shape[0]
    d = cdist(x, x)
    big = 2.0 * float(d.max()) + 1.0  # any tour not keeping start next to the dummy pays this
    full = np.zeros((n + 1, n + 1))
    full[:n, :n] = d
    full[0, 1:n] += big
    full[1:n, 0] += big
    scale = 1e6 / max(float(full.max()), 1e-300)
    ints = np.rint(full * scale).astype(int).tolist()
    return [int(v) for v in elkai.DistanceMatrix(ints).solve_tsp(runs=runs)[:-1]]


def open_tour(
    points: np.ndarray,
    start: np.ndarray | None = None,
    *,
    weights: np.ndarray | None = None,
    solver: Literal["fast", "lkh"] = "fast",
    rng: np.random.Generator | None = None,
    n_neighbours: int = 6,
    n_kicks: int | None = None,
    time_limit: float | None = None,
    lkh_runs: int = 1,
) -> OpenTour:
    """Shortest open tour from ``start`` through all ``points`` (free end).

    Parameters
    ----------
    points : ndarray, shape (N, D)
        Points to visit, N >= 1.
    start : ndarray, shape (D,), optional
        Fixed first position (default: the origin). Not part of ``order``.
    weights : ndarray, shape (D,), optional
        Per-coordinate scale of the metric ``‖diag(w)(p - q)‖`` (default ones).
    solver : {"fast", "lkh"}
        Heuristic of this module or LKH-3 via elkai.
    rng : numpy.random.Generator, optional
        Kick randomness of the fast solver (default: seed 0, deterministic).
    n_neighbours : int
        Candidate-list size K of the local search.
    n_kicks : int, optional
        Iterated-local-search kicks; default ``2 N / 3`` (≈ 25 ms for N = 300).
    time_limit : float, optional
        Seconds after which no further kick is tried (fast solver).
    lkh_runs : int
        LKH ``RUNS`` parameter.

    Raises
    ------
    PlanningError
        Empty or non-finite points, or a start of the wrong dimension.
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[0] < 1:
        raise PlanningError(f"points must be a non-empty (N, D) array, got shape {p.shape}")
    s = np.zeros(p.shape[1]) if start is None else np.asarray(start, dtype=float)
    w = np.ones(p.shape[1]) if weights is None else np.asarray(weights, dtype=float)
    if s.shape != (p.shape[1],) or w.shape != (p.shape[1],):
        raise PlanningError("start and weights must have one entry per coordinate")
    if not (np.all(np.isfinite(p)) and np.all(np.isfinite(s)) and np.all(w > 0)):
        raise PlanningError("points and start must be finite, weights positive")
    x = np.vstack([s[None], p]) * w
    n = p.shape[0]
    if n <= 2:
        orders = [[0]] if n == 1 else [[0, 1], [1, 0]]
        best = min(orders, key=lambda o: path_length(s, p, np.array(o), w))
        order = np.array(best)
    else:
        if solver == "fast":
            rng = np.random.default_rng(0) if rng is None else rng
            kicks = (2 * n) // 3 if n_kicks is None else int(n_kicks)
            tour = _fast(x, rng, n_neighbours, kicks, time_limit)
        elif solver == "lkh":
            tour = _lkh(x, lkh_runs)
        else:
            raise PlanningError(f"unknown TSP solver {solver!r}")
        i0 = tour.index(0)
        path = tour[i0:] + tour[:i0]
        if path[1] == n + 1:  # the dummy follows the start: walk the other way
            path = [0] + path[1:][::-1]
        order = np.array([v - 1 for v in path[1:] if v != n + 1], dtype=int)
    return OpenTour(order=order, length=path_length(s, p, order, w))
