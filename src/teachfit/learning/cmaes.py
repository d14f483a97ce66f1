"""CMA-ES (Hansen's ``cma`` package) behind the ask/tell :class:`~teachfit.learning.base.Learner`.

The search runs in the unit cube with ``cma``'s ``BoundTransform`` boundary handling (every
point asked lies in ``[0, 1]^d``), initial mean ``x0`` (default: the centre) and step size
``sigma0`` (unit-cube lengths). Sampling uses the learner's own seeded generator, not NumPy's
global state, so a learner rebuilt with the same seed asks the same points. When ``cma``'s
termination criteria fire (e.g. a converged step size) the strategy restarts from a fresh
random mean with the initial step size, so a trial budget is always used up.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from teachfit.core.params import LearningError, ParamSpace
from teachfit.learning.base import GenerationalLearner

# cma is imported where a strategy is made: it loads scipy.stats and pyplot (1-2 s)
if TYPE_CHECKING:
    import cma


class CMAES(GenerationalLearner):
    """CMA-ES learner.

    Parameters
    ----------
    space : ParamSpace
    seed : int
    sigma0 : float
        Initial step size in unit-cube lengths, within (0, 1].
    popsize : int or None
        Generation size; ``None`` uses CMA-ES's default ``4 + floor(3 ln d)``.
    x0 : sequence of float or None
        Initial mean in physical units (a mapping's values in ``space`` order is fine);
        ``None`` = the centre of the box.
    """

    def __init__(
        self,
        space: ParamSpace,
        seed: int = 0,
        sigma0: float = 0.3,
        popsize: int | None = None,
        x0: Sequence[float] | None = None,
    ) -> None:
        super().__init__(space)
        if not 0 < sigma0 <= 1:
            raise LearningError(f"sigma0 must be within (0, 1] (unit cube), got {sigma0}")
        if popsize is not None and popsize < 2:
            raise LearningError(f"popsize must be >= 2, got {popsize}")
        self.seed = int(seed)
        self.sigma0 = float(sigma0)
        self.popsize = popsize
        if x0 is None:
            self._x0 = np.full(space.dim, 0.5)
        else:
            if len(x0) != space.dim:
                raise LearningError(f"x0 needs {space.dim} values, got {len(x0)}")
            self._x0 = space.to_unit(dict(zip(space.names, x0, strict=True)))
        self._rng = np.random.default_rng(self.seed)
        self._restarts = 0
        self._es = self._make_es(self._x0)

    def _make_es(self, x0: np.ndarray) -> cma.CMAEvolutionStrategy:
        import cma

        rng = self._rng
        opts = {
            "bounds": [0.0, 1.0],
            "verbose": -9,
            "seed": int(rng.integers(1, 2**31 - 1)),
            # sample from our generator, not NumPy's global one (reproducible restores)
            "randn": lambda *shape: rng.standard_normal(shape),
        }
        if self.popsize is not None:
            opts["popsize"] = self.popsize
        if self.space.dim == 1:
            # cma does not run in 1-D; a dummy second coordinate that nothing reads fixes that
            x0 = np.append(x0, 0.5)
        return cma.CMAEvolutionStrategy(list(x0), self.sigma0, opts)

    def _key(self, gen: int, k: int) -> str:
        return f"r{self._restarts}g{gen}m{k}"

    def _new_generation(self) -> list[np.ndarray]:
        if self._es.stop():
            self._restarts += 1
            self._es = self._make_es(self._rng.uniform(0.0, 1.0, self.space.dim))
        self._asked = [np.asarray(x, dtype=float) for x in self._es.ask()]
        return [np.clip(x[: self.space.dim], 0.0, 1.0) for x in self._asked]

    def _end_generation(self, points: list[np.ndarray], costs: list[float]) -> None:
        if self.space.dim == 1:
            points = [np.append(p, a[1]) for p, a in zip(points, self._asked, strict=True)]
        self._es.tell([np.asarray(p, dtype=float) for p in points], list(costs))

    @property
    def mean(self) -> dict[str, float]:
        """Current distribution mean in physical units."""
        return self.space.from_unit(np.clip(self._es.mean[: self.space.dim], 0.0, 1.0))
