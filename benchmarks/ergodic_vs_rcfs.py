"""Ergodic coverage against RCFS's spectral multiscale coverage, side by side.

Usage: ``python benchmarks/ergodic_vs_rcfs.py [--lengths 2.5,5,10,20,40] [--markdown FILE]``

On the unit box (the search box's units: a path of length 1 crosses it once) and from RCFS's
start (0.1, 0.3), for a Gaussian and RCFS's own two-Gaussian mixture: the ergodic metric (16
cosine coefficients per dimension, as every search table) of RCFS's SMC loop
(``benchmarks/rcfs_smc.py``, a re-implementation from the published equations), of our
spectral coverage alone (``ergodic_trajectory``), of the default planner (``ergodic_search``,
method ``ergodic``: spectral coverage, then trajectory optimisation at the asked length, 200
L-BFGS iterations) and of ``ergodic-opt`` (the same, 1000 iterations), each with its path
length and planning time (wall clock, one call; RCFS runs until its path has the length).
``--markdown FILE`` appends the table.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from rcfs_smc import mixture_coefficients, smc_path

from teachfit.cli.script_markdown import add_markdown_option, append_table, checked_markdown, table
from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.ergodic import ergodic_metric, ergodic_trajectory
from teachfit.trajectories.ergodic_opt import ergodic_search

BOX = (np.zeros(2), np.ones(2))
START = np.array([0.1, 0.3])  # RCFS's x0


def distributions() -> dict[str, ExplorationDistribution]:
    """A Gaussian and RCFS's two-Gaussian mixture, on the unit box."""
    gauss = ExplorationDistribution(
        ("x", "y"), np.ones(1), np.array([[0.55, 0.45]]), np.array([[[0.02, 0.006], [0.006, 0.01]]])
    )
    v1, v2 = np.array([0.3, 0.1]), np.array([0.1, 0.2])
    covs = np.array(
        [np.outer(v1, v1) * 0.5 + np.eye(2) * 5e-3, np.outer(v2, v2) * 0.3 + np.eye(2) * 1e-2]
    )
    mix = ExplorationDistribution(
        ("x", "y"), np.full(2, 0.5), np.array([[0.5, 0.7], [0.6, 0.3]]), covs
    )
    return {"Gaussian": gauss, "RCFS mixture": mix}


#: a planner: (distribution, length) -> states (T, D) sampled uniformly in time
Planner = Callable[[ExplorationDistribution, float], np.ndarray]


def _rcfs(expl: ExplorationDistribution, length: float) -> np.ndarray:
    w_hat = mixture_coefficients(expl.weights, expl.means, expl.covs)
    return smc_path(w_hat, START, length)[0]


def _smc(expl: ExplorationDistribution, length: float) -> np.ndarray:
    return ergodic_trajectory(expl, speed=1.0, length=length, start=START, box=BOX).states


def _ours(iterations: int) -> Planner:
    def plan(expl: ExplorationDistribution, length: float) -> np.ndarray:
        kw = {"start": START, "box": BOX, "iterations": iterations}
        return ergodic_search(expl, speed=1.0, length=length, **kw).states

    return plan


PLANNERS: dict[str, Planner] = {
    "RCFS SMC": _rcfs,
    "ours: SMC only": _smc,
    "default (`ergodic`)": _ours(200),
    "`ergodic-opt`": _ours(1000),
}


def _cell(
    plan: Planner, expl: ExplorationDistribution, length: float
) -> tuple[float, float, float]:
    """(ergodic metric, path length, planning seconds) of one planner."""
    t0 = time.perf_counter()
    states = plan(expl, length)
    sec = time.perf_counter() - t0
    metric = ergodic_metric(states, expl, box=BOX, n_coeffs=16)
    return metric, float(np.linalg.norm(np.diff(states, axis=0), axis=1).sum()), sec


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--lengths", default="2.5,5,10,20,40", help="path lengths (box sides)")
    add_markdown_option(ap)
    args = ap.parse_args(argv)
    markdown = checked_markdown(ap, args.markdown)
    lengths = [float(v) for v in args.lengths.split(",")]
    print(f"{'distribution':>13} {'length':>6} " + " ".join(f"{k:>28}" for k in PLANNERS))
    rows = []
    for name, expl in distributions().items():
        for length in lengths:
            cells = [_cell(plan, expl, length) for plan in PLANNERS.values()]
            ref = cells[0][0]
            text = [f"{m:.2e} ({m / ref:.2f}x), L {n:.2f}, {s:.2f} s" for m, n, s in cells]
            print(f"{name:>13} {length:>6} " + " ".join(f"{c:>28}" for c in text), flush=True)
            rows.append([name, f"{length:g}", *text])
    title = (
        "**Ergodic metric against RCFS's SMC** (unit box, start (0.1, 0.3); metric (ratio to "
        "RCFS's), path length, planning time)"
    )
    append_table(ap, markdown, table(title, ["distribution", "asked length", *PLANNERS], rows))


if __name__ == "__main__":
    main()
