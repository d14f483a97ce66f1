"""The learning metric (Johannsmeier et al. 2019, Def. 5): ``(success, cost)`` of one execution.

Johannsmeier et al.'s cost for peg-in-hole: the execution time from first contact to full insertion;
when the error condition fired (e.g. the time limit), the maximum time plus a factor times the
distance still to go to the goal pose in the hole:

    success:  q = t_end - t_contact                                   (s)
    failure:  q = t_max + k_d * d_remaining                           (s + s/m * m)

so every failure costs more than every success (``t_end <= t_max``), and among failures the
ones that got closer cost less. Without a measured contact the success cost is ``t_end``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from teachfit.core.errors import SkillError
from teachfit.execution.engine import ExecutionResult


@dataclass(frozen=True)
class LearningMetric:
    """``time_limit`` ``t_max`` (s) and ``distance_factor`` ``k_d`` (s/m)."""

    time_limit: float = 5.0
    distance_factor: float = 100.0

    def __post_init__(self) -> None:
        if not (self.time_limit > 0 and self.distance_factor >= 0):
            raise SkillError("time_limit must be > 0 and distance_factor >= 0")

    def failure_cost(self, remaining: float) -> float:
        """``t_max + k_d * remaining`` (a non-finite distance counts as 1 m)."""
        d = remaining if math.isfinite(remaining) else 1.0
        return self.time_limit + self.distance_factor * max(d, 0.0)

    def evaluate(self, trace: ExecutionResult) -> tuple[bool, float]:
        """``(success, cost)`` of one execution."""
        if trace.success:
            start = trace.t_first_contact if math.isfinite(trace.t_first_contact) else 0.0
            return True, max(0.0, trace.t_end - start)
        return False, self.failure_cost(trace.remaining)
