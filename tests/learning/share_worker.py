"""The shared study of the tests whose processes work on one study (``test_study.py``,
``test_kill_points.py``): its space, its opening and a cheap cost that stands in for a robot."""

from __future__ import annotations

import time

from teachfit.learning import ParamDomain, ParamSpace, Study

SPACE = ParamSpace({"a": ParamDomain(-1.0, 1.0), "b": ParamDomain(0.0, 2.0)})
OPTIONS = {"cmaes": {"popsize": 4}, "pso": {"swarm_size": 4}, "lhs": {"n": 40}}


def open_shared(url: str, method: str) -> Study:
    return Study(
        url,
        task="puzzle",
        skill="peg-in-hole",
        space=SPACE,
        method=method,
        seed=7,
        options=OPTIONS[method],
        penalty=500.0,
    )


def cost(p: dict[str, float], sleep_s: float = 0.0) -> tuple[float, bool]:
    """Rosenbrock in (a, b), infeasible where a > 0.8; ``sleep_s`` stands in for a robot."""
    time.sleep(sleep_s)
    a, b = p["a"], p["b"]
    return ((1 - a) ** 2 + 100 * (b - a * a) ** 2, True) if a <= 0.8 else (500.0, False)
