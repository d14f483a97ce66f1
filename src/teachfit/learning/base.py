"""What every learner shares: a box-bounded parameter space and the ask/tell protocol.

A :class:`ParamSpace` names the learned parameters and their :class:`ParamDomain`
``[low, high]`` in physical units. Learners search the unit cube ``u in [0, 1]^d``:

    x_i = low_i + u_i (high_i - low_i)                       (linear domain)
    x_i = exp(log low_i + u_i (log high_i - log low_i))      (``log=True``, low_i > 0)

so that one step size means the same for every parameter. A learner hands out
:class:`Candidate` s (a unique ``key`` and a unit-cube point ``u``) with :meth:`Learner.ask` and is
told each one's cost with :meth:`Learner.tell`. Costs are minimised; a failed execution is told
with a penalty cost and ``feasible=False``. :meth:`Learner.restore` rebuilds a fresh learner's
state from finished trials (e.g. read back from a study database), after which asking continues
where the learner stood: finished keys are never handed out again.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from teachfit.core.params import LearningError, ParamSpace


@dataclass(frozen=True)
class Candidate:
    """A point handed out by a learner: unique ``key`` and unit-cube coordinates ``u`` (d,)."""

    key: str
    u: tuple[float, ...]

    @classmethod
    def of(cls, key: str, u: Sequence[float] | np.ndarray) -> Candidate:
        arr = np.clip(np.asarray(u, dtype=float).reshape(-1), 0.0, 1.0)
        return cls(key, tuple(float(x) for x in arr))


@dataclass(frozen=True)
class Finished:
    """A finished trial as a learner needs it for :meth:`Learner.restore`."""

    candidate: Candidate
    cost: float
    feasible: bool = True


@dataclass(frozen=True)
class TrialResult:
    """What one trial's objective returns: cost (minimised), feasibility, extra numbers."""

    cost: float
    feasible: bool = True
    info: Mapping[str, float] = field(default_factory=dict)


@runtime_checkable
class Learner(Protocol):
    """Ask/tell black-box minimiser over a :class:`ParamSpace` (unit cube inside)."""

    space: ParamSpace

    def ask(self) -> Candidate | None:
        """The next candidate, or ``None`` if none can be handed out before pending tells
        arrive (a population-based learner waiting for its generation) or ever again."""
        ...

    def tell(self, candidate: Candidate, cost: float, feasible: bool = True) -> None:
        """Report a finished candidate's (finite) cost; ``candidate.u`` is taken as evaluated."""
        ...

    def restore(self, finished: Sequence[Finished]) -> None:
        """On a fresh learner: adopt previously finished trials as if told, in their order."""
        ...

    def release(self, candidate: Candidate) -> Candidate | None:
        """``candidate.key`` is claimed by another process sharing the study. Returns the same
        point under a fresh key to claim instead, or ``None``: the learner then waits for that
        key's result from the other process (:meth:`adopt`)."""
        ...

    def adopt(self, finished: Finished) -> None:
        """A trial finished by another process sharing the study (or re-run here after its
        process died): take it as told. Keys this learner has no use for are ignored."""
        ...


class GenerationalLearner:
    """Base of population learners (CMA-ES, PSO): generations of keyed candidates.

    Subclasses implement :meth:`_new_generation` (unit points of the next generation) and
    :meth:`_end_generation` (update from the whole generation's points and costs). Candidates
    of one generation may be told in any order; the next generation starts once all are told.
    :meth:`restore` replays generations, substituting every stored trial's point and cost for
    the member with the same key, so the state rebuilt equals the one the killed run had for
    the completed generations, and only the unfinished members of the current one are asked.
    """

    space: ParamSpace

    def __init__(self, space: ParamSpace) -> None:
        self.space = space
        self._gen = -1
        self._members: list[Candidate] = []
        self._told: dict[str, tuple[Candidate, float]] = {}
        self._queue: list[Candidate] = []
        self._restored: dict[str, Finished] = {}

    # ----------------------------------------------------------------------- subclass API
    def _new_generation(self) -> list[np.ndarray]:
        raise NotImplementedError

    def _end_generation(self, points: list[np.ndarray], costs: list[float]) -> None:
        raise NotImplementedError

    def _key(self, gen: int, k: int) -> str:
        return f"g{gen}m{k}"

    # ----------------------------------------------------------------------- mechanics
    def _start_generation(self) -> None:
        self._gen += 1
        points = self._new_generation()
        self._members = [Candidate.of(self._key(self._gen, k), p) for k, p in enumerate(points)]
        self._told = {}
        self._queue = []
        for cand in self._members:
            # members finished before a restart are told from the store, not asked again
            done = self._restored.pop(cand.key, None)
            if done is None:
                self._queue.append(cand)
            else:
                self._record(done.candidate, done.cost)

    def _record(self, candidate: Candidate, cost: float) -> None:
        keys = [m.key for m in self._members]
        if candidate.key not in keys:
            raise LearningError(f"candidate {candidate.key!r} is not of the current generation")
        if candidate.key in self._told:
            raise LearningError(f"candidate {candidate.key!r} was already told")
        if not math.isfinite(cost):
            raise LearningError(f"cost of {candidate.key!r} must be finite, got {cost}")
        self._told[candidate.key] = (candidate, float(cost))
        if len(self._told) == len(self._members):
            points = [np.asarray(self._told[k][0].u) for k in keys]
            costs = [self._told[k][1] for k in keys]
            self._end_generation(points, costs)
            self._members = []

    def ask(self) -> Candidate | None:
        if not self._members:
            self._start_generation()
        return self._queue.pop(0) if self._queue else None

    def tell(self, candidate: Candidate, cost: float, feasible: bool = True) -> None:
        self._record(candidate, cost)

    def release(self, candidate: Candidate) -> Candidate | None:
        return None  # a key names a member: every process asks the same one

    def adopt(self, finished: Finished) -> None:
        key = finished.candidate.key
        if not any(m.key == key for m in self._members):
            self._restored[key] = finished  # of a later generation: told when it starts
        elif key not in self._told:
            self._queue = [c for c in self._queue if c.key != key]
            self._record(finished.candidate, finished.cost)

    def restore(self, finished: Sequence[Finished]) -> None:
        if self._gen >= 0:
            raise LearningError("restore() needs a fresh learner")
        self._restored = {f.candidate.key: f for f in finished}
        while self._restored:
            self._start_generation()
            if self._members:  # the generation the run stopped in
                break
        if self._restored:
            raise LearningError(
                f"stored trials {sorted(self._restored)[:5]} do not fit this learner's "
                "generations (other population size or options?)"
            )
