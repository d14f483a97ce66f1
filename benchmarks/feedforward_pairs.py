"""Ehlers et al.'s feed-forward ablation as paired runs, one N at a time (results survive a stop).

Usage: ``python benchmarks/feedforward_pairs.py [--robot fr3] [--trajectories 20]
[--sizes 100,200,400] [--seed 0] [--workers 1]``

For each N, ``--trajectories`` TSHIX trajectories from Table II's start, each executed with
and without the GMR feed-forward (the same seeds, start and demonstration:
:func:`teachfit.bench.search.table2` with one size), printed as a markdown table with Wilson
95 % intervals beside the paper's Table II (with) and ablation (without) figures.
"""

from __future__ import annotations

import argparse
import time

from teachfit.bench import search
from teachfit.metrics.stats import wilson_interval


def _rate(s: int, n: int) -> str:
    lo, hi = wilson_interval(s, n)
    return f"{s}/{n} = {100 * s / n:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}]"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--robot", default="fr3")
    ap.add_argument("--trajectories", type=int, default=20)
    ap.add_argument("--sizes", default="100,200,400")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=1)
    args = ap.parse_args()
    search.use_robot(args.robot)
    print("| N | with feed-forward | without | paper with | paper without | wall |")
    print("| --- | --- | --- | --- | --- | --- |")
    for n in (int(s) for s in args.sizes.split(",")):
        t0 = time.monotonic()
        (ff,), (no,) = search.table2(args.seed, (n,), args.trajectories, (n,), workers=args.workers)
        paper = [search.PAPER_TABLE2.get(n), search.PAPER_ABLATION.get(n)]
        cells = [_rate(r.ours.successes, r.ours.trials) for r in (ff, no)]
        cells += ["n/a" if p is None else _rate(*p) for p in paper]
        print(f"| {n} | " + " | ".join(cells) + f" | {time.monotonic() - t0:.0f} s |", flush=True)


if __name__ == "__main__":
    main()
