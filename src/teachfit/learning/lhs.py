"""Latin hypercube sampling (``scipy.stats.qmc``): the uninformed reference learner.

A design of ``n`` points is drawn once (seeded, optionally optimised by ``random-cd``); trial
``i`` evaluates point ``i``. Tells change nothing but the bookkeeping; after ``n`` points the
learner has nothing more to ask.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.stats import qmc

from teachfit.core.params import LearningError, ParamSpace
from teachfit.learning.base import Candidate, Finished


class LatinHypercube:
    """Latin hypercube learner over ``space`` with a design of ``n`` points."""

    def __init__(self, space: ParamSpace, n: int, seed: int = 0, optimise: bool = True) -> None:
        if n < 1:
            raise LearningError(f"a Latin hypercube needs n >= 1 points, got {n}")
        self.space = space
        self.n = int(n)
        optimization = "random-cd" if optimise and space.dim > 1 else None
        rng = np.random.default_rng(seed)
        sampler = qmc.LatinHypercube(d=space.dim, seed=rng, optimization=optimization)
        self.design = sampler.random(self.n)
        self._next = 0
        self._done: set[int] = set()
        self._out: set[int] = set()

    def ask(self) -> Candidate | None:
        while self._next < self.n and (self._next in self._done or self._next in self._out):
            self._next += 1
        if self._next >= self.n:
            return None
        i = self._next
        self._out.add(i)
        return Candidate.of(f"i{i}", self.design[i])

    def _index(self, key: str) -> int:
        try:
            i = int(key.removeprefix("i"))
        except ValueError:
            i = -1
        if not key.startswith("i") or not 0 <= i < self.n:
            raise LearningError(f"{key!r} is not a point of this {self.n}-point design")
        return i

    def tell(self, candidate: Candidate, cost: float, feasible: bool = True) -> None:
        i = self._index(candidate.key)
        if i in self._done:
            raise LearningError(f"candidate {candidate.key!r} was already told")
        self._out.discard(i)
        self._done.add(i)

    def release(self, candidate: Candidate) -> Candidate | None:
        return None  # point i is key i in every process

    def adopt(self, finished: Finished) -> None:
        i = self._index(finished.candidate.key)
        self._out.discard(i)
        self._done.add(i)

    def restore(self, finished: Sequence[Finished]) -> None:
        for f in finished:
            self.tell(f.candidate, f.cost, f.feasible)
