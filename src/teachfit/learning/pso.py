"""Particle swarm optimisation (global-best, synchronous) behind the ask/tell interface.

Written by hand: the well-kept PSO packages (pyswarms, scikit-opt, ...) drive the objective
themselves through a ``optimize(f)`` loop and offer no ask/tell interface, which a study that
stores and resumes every trial and evaluates them in worker processes needs.

In the unit cube, with inertia ``w`` and acceleration coefficients ``c1``, ``c2`` (Clerc &
Kennedy's constriction values by default), for particle ``i`` after each whole generation:

    v_i <- w v_i + c1 r1 (p_i - x_i) + c2 r2 (g - x_i),   r1, r2 ~ U(0, 1)^d
    v_i <- clip(v_i, -v_max, v_max)
    x_i <- x_i + v_i, reflected back into [0, 1]^d (the velocity component flips sign)

where ``p_i`` is the particle's best point so far and ``g`` the swarm's. Initial positions are a
Latin hypercube over the cube, initial velocities uniform in ``[-v_max, v_max] / 2``.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import qmc

from teachfit.core.params import LearningError, ParamSpace
from teachfit.learning.base import GenerationalLearner


class PSO(GenerationalLearner):
    """Particle swarm learner; see the module docstring for the update.

    Parameters
    ----------
    space : ParamSpace
    seed : int
    swarm_size : int or None
        Particles per generation; ``None`` = ``10 + floor(2 sqrt(d))`` (SPSO 2006).
    inertia, c1, c2 : float
        ``w``, cognitive and social coefficients.
    v_max : float
        Velocity limit per coordinate (unit-cube lengths per generation).
    """

    def __init__(
        self,
        space: ParamSpace,
        seed: int = 0,
        swarm_size: int | None = None,
        inertia: float = 0.7298,
        c1: float = 1.49618,
        c2: float = 1.49618,
        v_max: float = 0.5,
    ) -> None:
        super().__init__(space)
        n = swarm_size if swarm_size is not None else 10 + int(2 * np.sqrt(space.dim))
        if n < 2:
            raise LearningError(f"swarm_size must be >= 2, got {n}")
        if not 0 <= inertia < 1 or c1 < 0 or c2 < 0 or not 0 < v_max <= 1:
            raise LearningError("need 0 <= inertia < 1, c1, c2 >= 0 and 0 < v_max <= 1")
        self.seed = int(seed)
        self.swarm_size = n
        self.inertia, self.c1, self.c2, self.v_max = inertia, c1, c2, v_max
        self._rng = np.random.default_rng(self.seed)
        d = space.dim
        self._x = qmc.LatinHypercube(d=d, seed=self._rng).random(n)
        self._v = self._rng.uniform(-v_max / 2, v_max / 2, (n, d))
        self._p = self._x.copy()
        self._p_cost = np.full(n, np.inf)
        self._g = self._x[0].copy()
        self._g_cost = np.inf

    def _new_generation(self) -> list[np.ndarray]:
        return [x.copy() for x in self._x]

    def _end_generation(self, points: list[np.ndarray], costs: list[float]) -> None:
        x = np.asarray(points)
        f = np.asarray(costs)
        better = f < self._p_cost
        self._p[better] = x[better]
        self._p_cost[better] = f[better]
        i = int(np.argmin(self._p_cost))
        if self._p_cost[i] < self._g_cost:
            self._g, self._g_cost = self._p[i].copy(), float(self._p_cost[i])
        r1 = self._rng.uniform(size=x.shape)
        r2 = self._rng.uniform(size=x.shape)
        v = self.inertia * self._v + self.c1 * r1 * (self._p - x) + self.c2 * r2 * (self._g - x)
        np.clip(v, -self.v_max, self.v_max, out=v)
        x = x + v
        low, high = x < 0.0, x > 1.0
        x[low], x[high] = -x[low], 2.0 - x[high]
        v[low | high] *= -1.0
        self._x = np.clip(x, 0.0, 1.0)
        self._v = v

    @property
    def best(self) -> tuple[dict[str, float], float]:
        """Swarm best (physical values, cost) so far."""
        return self.space.from_unit(self._g), self._g_cost
