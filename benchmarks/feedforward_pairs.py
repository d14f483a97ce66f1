"""Ehlers et al.'s feed-forward ablation as paired runs, one N at a time (results survive a stop).

Usage: ``python benchmarks/feedforward_pairs.py [--robot fr3] [--trajectories 20]
[--sizes 100,200,400] [--seed 0] [--workers 1] [--markdown FILE]``

For each N, ``--trajectories`` TSHIX trajectories from Table II's start, each executed with
and without the GMR feed-forward (the same seeds, start and demonstration:
:func:`teachfit.bench.search.table2` with one size), printed as a markdown table with Wilson
95 % intervals, the discordant pairs and their exact sign test (:func:`teachfit.metrics.stats.
paired_sign_test`), beside the paper's Table II (with) and ablation (without) figures, a row as
each N finishes. ``--markdown FILE`` appends the table when all have finished, headed with where it
came from (``benchmarks/results/feedforward-pairs-fr3.md`` feeds BENCHMARKS.md).
"""

from __future__ import annotations

import argparse
import time

from teachfit.bench import search
from teachfit.cli.script_markdown import add_markdown_option, append_table, checked_markdown, table
from teachfit.metrics.stats import paired_sign_test, wilson_interval

HEADER = (
    "N",
    "with feed-forward",
    "without",
    "pairs with : without (sign test p)",
    "paper with",
    "paper without",
    "wall",
)


def _rate(s: int, n: int) -> str:
    lo, hi = wilson_interval(s, n)
    return f"{s}/{n} = {100 * s / n:.0f} % [{100 * lo:.0f}, {100 * hi:.0f}]"


def pairs_row(seed: int, n: int, trajectories: int, workers: int) -> list[str]:
    """One N's paired runs with and without the feed-forward, beside the paper's figures."""
    t0 = time.monotonic()
    (ff,), (no,) = search.table2(seed, (n,), trajectories, (n,), workers=workers)
    paper = [search.PAPER_TABLE2.get(n), search.PAPER_ABLATION.get(n)]
    cells = [_rate(r.ours.successes, r.ours.trials) for r in (ff, no)]
    n_ff, n_no, p = paired_sign_test(ff.outcomes, no.outcomes)
    cells.append(f"{n_ff} : {n_no} (p = {p:.3g})")
    cells += ["n/a" if p is None else _rate(*p) for p in paper]
    return [str(n), *cells, f"{time.monotonic() - t0:.0f} s"]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--robot", default="fr3")
    ap.add_argument("--trajectories", type=int, default=20)
    ap.add_argument("--sizes", default="100,200,400")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=1)
    add_markdown_option(ap)
    args = ap.parse_args(argv)
    markdown = checked_markdown(ap, args.markdown)
    search.use_robot(args.robot)
    rows = []
    print("| " + " | ".join(HEADER) + " |")
    print("| " + " | ".join("---" for _ in HEADER) + " |")
    for n in (int(s) for s in args.sizes.split(",")):
        rows.append(pairs_row(args.seed, n, args.trajectories, args.workers))
        print("| " + " | ".join(rows[-1]) + " |", flush=True)
    title = (
        f"**Feed-forward ablation on the {args.robot}, {args.trajectories} paired trajectories "
        "per N** (Table II's start; the same seeds and demonstration with and without the GMR "
        "feed-forward)"
    )
    append_table(ap, markdown, table(title, HEADER, rows))


if __name__ == "__main__":
    main()
