"""One of several processes working on one shared study (run by ``test_study.py``).

``python share_worker.py URL BUDGET METHOD [SLEEP_S]``: opens the study, runs it to BUDGET
trials in this process (no worker pool) and prints ``finished=N restored=M``. With
``SHARE_WORKER_MARK=FILE`` it appends a line to FILE as each trial begins.
"""

from __future__ import annotations

import os
import sys
import time

from teachfit.learning import ParamDomain, ParamSpace, Study, run_study

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


def main() -> None:
    url, budget, method = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    sleep_s = float(sys.argv[4]) if len(sys.argv) > 4 else 0.0
    mark = os.environ.get("SHARE_WORKER_MARK")  # a line per trial begun, for the test

    def objective(p: dict[str, float]) -> tuple[float, bool]:
        if mark:
            with open(mark, "a") as fh:
                fh.write("trial\n")
        return cost(p, sleep_s)

    study = open_shared(url, method)
    rep = run_study(study, objective, budget, workers=0)
    print(f"finished={rep.finished} restored={rep.restored} holds={study.n_finished}", flush=True)


if __name__ == "__main__":
    main()
