"""Moves of the open-tour kernel (numba), used by :mod:`teachfit.trajectories.tsp_kernel`:
distances with the dummy end, reversals, segment moves, the Lin-Kernighan chain, a new free
end, the start tour and the candidate lists. The tour layout and why this is written here are
described in :mod:`teachfit.trajectories.tsp_kernel`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit
from numba.core.cpu import CPUTargetOptions

#: Decorator of the kernel's functions that allocate nothing: compiled without numba's
#: reference counting. Otherwise every array argument is counted up on entry and down on exit
#: by an atomic instruction, which no pass removes across calls (numba issue #2345): in these
#: small functions, called per node and per candidate, that was 45 % of the solver's CPU
#: (``perf``, 300 points). The same tours, bit for bit; plain ``njit`` where numba lacks the
#: option.
_LEAF: dict[str, Any] = {"cache": True}
if hasattr(CPUTargetOptions, "_nrt"):
    _LEAF["_nrt"] = False
leaf = njit(**_LEAF)
#: the same, inlined into each caller (numba's IR inlining; LLVM leaves these calls, which
#: pass every array as a struct): ``_d`` (25 % of the solver's CPU as a call), the per-node
#: moves into the local search's loop and the per-candidate helpers (with the local search a
#: leaf: a fifth less CPU at 100-300 points, none at 1000; the same tours; cold compilation
#: ~2 s longer; 2026-12-06)
inlined_leaf = njit(inline="always", **_LEAF)


@inlined_leaf
def _d(x: np.ndarray, a: int, b: int, dummy: int) -> float:
    """Distance of nodes ``a`` and ``b``: ``x[a, b]`` when ``x`` is the distance matrix (a row
    per node, the dummy's included: ``dummy + 1`` rows), else Euclidean between the rows of the
    coordinates ``x`` (``dummy`` rows), 0 to the dummy (``dummy = -1``: none)."""
    if x.shape[0] == dummy + 1:
        return x[a, b]
    if a == dummy or b == dummy:
        return 0.0
    s = 0.0
    for k in range(x.shape[1]):
        t = x[a, k] - x[b, k]
        s += t * t
    return np.sqrt(s)


@njit(cache=True)
def nearest_neighbour_path(x: np.ndarray, neigh: np.ndarray) -> np.ndarray:
    """Greedy path from node 0 always to the nearest unvisited node (candidates first, a full
    scan only when all of them are visited); returns the node order, shape (n,)."""
    n = x.shape[0]
    left = np.ones(n, dtype=np.bool_)
    order = np.empty(n, dtype=np.int64)
    cur = 0
    left[0] = False
    order[0] = 0
    for k in range(1, n):
        nxt = -1
        for c in neigh[cur]:  # nearest first
            if left[c]:
                nxt = c
                break
        if nxt < 0:
            best = np.inf
            for c in range(n):
                if left[c]:
                    dc = _d(x, cur, c, -1)
                    if dc < best:
                        best, nxt = dc, c
        left[nxt] = False
        order[k] = nxt
        cur = nxt
    return order


@njit(cache=True)
def merge_candidates(
    x: np.ndarray, near: np.ndarray, indptr: np.ndarray, indices: np.ndarray, width: int
) -> np.ndarray:
    """Candidate lists, shape (n, width): each node's nearest nodes ``near`` (rows may hold
    the node itself) merged with its Delaunay neighbours ``indices[indptr[v]:indptr[v+1]]``,
    nearest first, at most ``width``, padded by repeating the last."""
    n = x.shape[0]
    out = np.empty((n, width), dtype=np.int64)
    buf = np.empty(near.shape[1] + n, dtype=np.int64)
    dist = np.empty(near.shape[1] + n, dtype=np.float64)
    seen = np.zeros(n, dtype=np.bool_)
    for v in range(n):
        c = 0
        seen[v] = True
        for u in near[v]:
            if not seen[u]:
                seen[u] = True
                buf[c] = u
                c += 1
        for k in range(indptr[v], indptr[v + 1]):
            u = indices[k]
            if not seen[u]:
                seen[u] = True
                buf[c] = u
                c += 1
        for k in range(c):
            dist[k] = _d(x, v, buf[k], -1)
            seen[buf[k]] = False
        seen[v] = False
        idx = np.argsort(dist[:c], kind="mergesort")
        w = min(width, c)
        for k in range(w):
            out[v, k] = buf[idx[k]]
        for k in range(w, width):
            out[v, k] = out[v, w - 1]
    return out


@njit(cache=True)
def candidate_distances(x: np.ndarray, neigh: np.ndarray) -> np.ndarray:
    """``nd[a, k] = d(a, neigh[a, k])``, shape (M - 1, K): the candidate scans read a node's
    row of K distances, in cache, instead of K scattered matrix entries or square roots (the
    same values, so the same tours; 4 % less CPU at 300 points, 8 % at 1000)."""
    dummy = neigh.shape[0]
    nd = np.empty(neigh.shape)
    for a in range(neigh.shape[0]):
        for k in range(neigh.shape[1]):
            nd[a, k] = _d(x, a, neigh[a, k], dummy)
    return nd


@leaf
def _reverse(tour: np.ndarray, pos: np.ndarray, i: int, j: int) -> None:
    """Reverse ``tour[i..j]`` in place and keep ``pos`` (node -> index) in step."""
    while i < j:
        a, b = tour[i], tour[j]
        tour[i], tour[j] = b, a
        pos[b], pos[a] = i, j
        i += 1
        j -= 1


@leaf
def _move_segment(
    tour: np.ndarray, pos: np.ndarray, s: int, e: int, q: int, flip: bool
) -> tuple[int, int]:
    """Move ``tour[s..e]`` between ``tour[q]`` and ``tour[q+1]`` (``q`` outside ``s-1..e``),
    reversed if ``flip``; returns the index range that changed."""
    n_seg = e - s + 1
    if q > e:  # A B -> B A, with B = tour[e+1..q]
        _reverse(tour, pos, s, q)  # rev(B) rev(A)
        _reverse(tour, pos, s, q - n_seg)  # B rev(A)
        if not flip:
            _reverse(tour, pos, q - n_seg + 1, q)  # B A
        return s, q
    # B A -> A B, with B = tour[q+1..s-1]
    _reverse(tour, pos, q + 1, e)  # rev(A) rev(B)
    _reverse(tour, pos, q + 1 + n_seg, e)  # rev(A) B
    if not flip:
        _reverse(tour, pos, q + 1, q + n_seg)  # A B
    return q + 1, e


@leaf
def _flip(tour: np.ndarray, pos: np.ndarray, t1: int, t2: int, t3: int, flips: np.ndarray, k: int):
    """The 2-opt flip of a Lin-Kernighan step: remove ``(t1, t2)`` and ``(t3, t4)``, add
    ``(t2, t3)`` and ``(t4, t1)``, ``t4`` the neighbour of ``t3`` on ``t2``'s side; records the
    reversed range in ``flips[k]``. Returns ``t4``, or -1 when the flip would move an end."""
    i, j = pos[t1], pos[t2]
    direction = j - i  # +1: t2 follows t1
    c = pos[t3]
    p4 = c - direction
    if p4 < 0 or p4 >= tour.shape[0]:
        return -1
    t4 = tour[p4]
    if t4 == t2 or t3 == t1:
        return -1
    if direction == 1:
        lo, hi = (j, p4) if c > i else (c, i)
    else:
        lo, hi = (p4, j) if c < i else (i, c)
    if lo < 1 or hi > tour.shape[0] - 2 or lo > hi:
        return -1
    _reverse(tour, pos, lo, hi)
    flips[k, 0], flips[k, 1] = lo, hi
    return t4


@leaf
def _best_step(
    x: np.ndarray,
    neigh: np.ndarray,
    nd: np.ndarray,
    tour: np.ndarray,
    pos: np.ndarray,
    t1: int,
    t2: int,
    g: float,
    eps: float,
) -> tuple[float, int]:
    """The candidate ``t3`` of ``t2`` with positive partial gain ``g - d(t2, t3)`` and the
    largest ``d(t3, t4) - d(t2, t3)``; returns (that value, t3), t3 = -1 when none."""
    m = tour.shape[0]
    dummy = m - 1
    best_val, best_t3 = -1e300, -1
    direction = pos[t2] - pos[t1]
    for kk in range(neigh.shape[1]):
        t3, d23 = neigh[t2, kk], nd[t2, kk]
        if g - d23 <= eps:
            break
        if t3 == t1:
            continue
        p4 = pos[t3] - direction
        if p4 < 0 or p4 >= m:
            continue
        t4 = tour[p4]
        if t4 == t2:
            continue
        val = _d(x, t3, t4, dummy) - d23
        if val > best_val:
            best_val, best_t3 = val, t3
    return best_val, best_t3


# Long on purpose (> 60 lines): one Lin-Kernighan chain, compiled; its depth loop keeps the
# chain's partial gain, flips and best closing point in locals that a split would pass around.
@leaf
def _lk_node(
    x: np.ndarray,
    neigh: np.ndarray,
    nd: np.ndarray,
    tour: np.ndarray,
    pos: np.ndarray,
    t1: int,
    eps: float,
    flips: np.ndarray,
    breadth: int,
) -> tuple[float, int]:
    """A Lin-Kernighan chain of up to ``flips.shape[0]`` 2-opt flips from ``t1`` (positive
    partial gains; ``breadth`` alternatives at the first step, then the best
    ``d(t3, t4) - d(t2, t3)``), cut at its best closed gain.

    Returns (gain, number of flips kept in ``flips``); (0, 0) with the tour unchanged when no
    chain gains."""
    m = tour.shape[0]
    dummy = m - 1
    depth_max = flips.shape[0]
    for side in range(2):
        p2 = pos[t1] + (1 if side == 0 else -1)
        if p2 < 0 or p2 >= m:
            continue
        t2_0 = tour[p2]
        if t2_0 == dummy:  # no candidate list: every node is at distance 0 from it
            continue
        g0 = _d(x, t1, t2_0, dummy)
        tried = 0
        for kk in range(neigh.shape[1]):
            t3_0, d23 = neigh[t2_0, kk], nd[t2_0, kk]
            if tried >= breadth:
                break
            if g0 - d23 <= eps:
                break
            t4 = _flip(tour, pos, t1, t2_0, t3_0, flips, 0)
            if t4 < 0:
                continue
            tried += 1
            g = g0 - d23 + _d(x, t3_0, t4, dummy)
            best, best_k = g - _d(x, t4, t1, dummy), 1
            k = 1
            t2 = t4
            while k < depth_max:
                best_val, best_t3 = -1e300, -1
                if t2 == dummy:  # the free end: any node is at distance 0, take the longest edge
                    direction = pos[t2] - pos[t1]
                    for c in range(1, m - 1):
                        t3 = tour[c]
                        t4c = tour[c - direction]
                        if t3 == t1 or t4c == t2:
                            continue
                        val = _d(x, t3, t4c, dummy)
                        if val > best_val:
                            best_val, best_t3 = val, t3
                else:
                    best_val, best_t3 = _best_step(x, neigh, nd, tour, pos, t1, t2, g, eps)
                if best_t3 < 0:
                    break
                t4 = _flip(tour, pos, t1, t2, best_t3, flips, k)
                if t4 < 0:
                    break
                g += best_val
                k += 1
                t2 = t4
                closed = g - _d(x, t4, t1, dummy)
                if closed > best:
                    best, best_k = closed, k
            for r in range(k - 1, best_k - 1, -1):  # undo the flips past the best
                _reverse(tour, pos, flips[r, 0], flips[r, 1])
            if best > eps:
                return best, best_k
            for r in range(best_k - 1, -1, -1):
                _reverse(tour, pos, flips[r, 0], flips[r, 1])
    return 0.0, 0


@inlined_leaf
def _insertion_gain(
    x: np.ndarray, tour: np.ndarray, b: int, p: int, q: int, dummy: int
) -> tuple[float, bool]:
    """Gain of putting the segment ``b..p`` between ``tour[q]`` and ``tour[q+1]``, the better
    way round, and whether that is reversed (``p..b``)."""
    left, right = tour[q], tour[q + 1]
    old = _d(x, left, right, dummy)
    fwd = old - _d(x, left, b, dummy) - _d(x, p, right, dummy)
    rev = old - _d(x, left, p, dummy) - _d(x, b, right, dummy)
    return (rev, True) if rev > fwd else (fwd, False)


# Long on purpose (> 60 lines): compiled candidate scan of one move kind; its gains share the
# locals of the two loops.
@inlined_leaf
def _or_segment(
    x: np.ndarray,
    neigh: np.ndarray,
    nd: np.ndarray,
    tour: np.ndarray,
    pos: np.ndarray,
    a: int,
    eps: float,
) -> tuple[float, int, int]:
    """Or-opt of a segment of any length: the segment ``S = tour[i+1..j-1]`` between ``a =
    tour[i]`` and a candidate ``c = tour[j]`` of ``a`` is cut out (``a`` joined to ``c``) and
    put, either way round, next to a candidate of its first or last node that is nearer to it
    than the cut gains (positive partial gain: about 40 % of the CPU of trying all candidates,
    which saves about a quarter of the kernel's CPU at 300 points and pays for the other
    moves). Applies the first improving one; returns (gain, lo, hi) like
    :func:`_move_segment` (gain 0: none)."""
    m = tour.shape[0]
    dummy = m - 1
    i = pos[a]
    if i > m - 3:
        return 0.0, 0, 0
    b = tour[i + 1]
    dab = _d(x, a, b, dummy)
    for kk in range(neigh.shape[1]):
        c, dac = neigh[a, kk], nd[a, kk]
        j = pos[c]
        if j <= i + 1 or j > m - 1:
            continue
        if dab - dac <= eps:
            break
        p = tour[j - 1]
        g1 = dab + _d(x, p, c, dummy) - dac
        for end in range(2):
            v = b if end == 0 else p
            for ke in range(neigh.shape[1]):
                e = neigh[v, ke]
                if g1 - nd[v, ke] <= eps:
                    break
                q0 = pos[e]
                for q in (q0 - 1, q0):
                    if q < 0 or q > m - 2 or (i <= q <= j - 1):
                        continue
                    g2, flip = _insertion_gain(x, tour, b, p, q, dummy)
                    if g1 + g2 > eps:
                        lo, hi = _move_segment(tour, pos, i + 1, j - 1, q, flip)
                        return g1 + g2, lo, hi
    return 0.0, 0, 0


@inlined_leaf
def _tail_move(
    x: np.ndarray,
    neigh: np.ndarray,
    nd: np.ndarray,
    tour: np.ndarray,
    pos: np.ndarray,
    a: int,
    eps: float,
) -> tuple[float, int, int]:
    """A new free end: the tour is cut at an edge of ``a``, ``(u, b) = (tour[i], tour[i+1])``,
    ``u`` becomes the last point and the tail ``b .. z`` (``z`` the last point so far) goes,
    either way round, between ``tour[q]`` and ``tour[q+1]`` before the cut, one of them a
    candidate of ``b`` nearer than ``u`` (positive partial gain). With the dummy at
    distance 0 this is a segment insertion whose gain starts with the whole edge ``(u, b)``;
    the other moves break the dummy's edge only next to a candidate of the last point, so the
    end moved mostly by kicks (19 of the 20 instances over 1.01 x LKH among 180 sets of 300
    points ended elsewhere than LKH's tour).
    Applies the first improving one; returns (gain, lo, hi) like :func:`_move_segment`."""
    m = tour.shape[0]
    dummy = m - 1
    z = tour[m - 2]
    for side in range(2):
        i = pos[a] if side == 0 else pos[a] - 1
        if i < 1 or i > m - 3:
            continue
        b = tour[i + 1]
        g1 = _d(x, tour[i], b, dummy)
        for ke in range(neigh.shape[1]):
            e, de = neigh[b, ke], nd[b, ke]
            if g1 - de <= eps:
                break
            q0 = pos[e]
            if q0 >= i:
                continue
            for q in (q0, q0 - 1):  # e = tour[q]: e b .. z ...; e = tour[q+1]: ... z .. b e
                if q < 0:
                    continue
                left, right = tour[q], tour[q + 1]
                far = _d(x, z, right, dummy) if q == q0 else _d(x, left, z, dummy)
                g = g1 - de + _d(x, left, right, dummy) - far
                if g > eps:
                    lo, hi = _move_segment(tour, pos, i + 1, m - 2, q, q != q0)
                    return g, lo, hi
    return 0.0, 0, -1
