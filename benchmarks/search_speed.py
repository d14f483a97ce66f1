"""Wall time of TSHIX (ours vs LKH via elkai) and of ergodic search, measured in one run.

Usage: ``python benchmarks/search_speed.py [--repeats 5] [--seed 0] [--part all|tshix|tsp]
[--sizes 100,300,1000,2000] [--instances 3] [--lkh-cache FILE] [--markdown FILE]``

For each N = 100..500 TSHIX plans ``repeats`` trajectories from a fixed 2-D exploration
distribution; the tour length of our open-tour solver is compared with LKH-3 (elkai) on the
same samples. Then one ergodic trajectory of the TSHIX (N = 300) length is generated in 2D and
3D (x, y, rz): the default (spectral coverage, then optimisation at that length) and
``ergodic-opt``. Last, the open-tour solver alone on three point families (uniform, Gaussian,
clustered: 8 clusters of 2 mm spread in a 40 mm square) against LKH-3 on the same points.
Times are medians of wall-clock seconds (``time.perf_counter``); the open-tour timings are
the solver's CPU time (``time.process_time``), which a loaded machine disturbs less.
``--markdown FILE`` appends the tables of the parts run (the TSHIX table at four of its sizes),
headed with where they came from (``benchmarks/results/search-speed-tshix.md``,
``search-speed-tsp.md`` feed BENCHMARKS.md).
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import time

import numpy as np

from teachfit.cli.script_markdown import add_markdown_option, append_table, checked_markdown, table
from teachfit.models.exploration import ExplorationDistribution
from teachfit.trajectories.ergodic import ergodic_metric
from teachfit.trajectories.ergodic_opt import ergodic_search
from teachfit.trajectories.tshix import SearchTrajectory, TshixPlanner, metric_weights
from teachfit.trajectories.tsp import open_tour


def _expl(dims: tuple[str, ...]) -> ExplorationDistribution:
    mean = np.array([0.01, 0.005, 0.05])[: len(dims)]
    cov = np.array([[1e-4, 2e-5, 0.0], [2e-5, 4e-5, 0.0], [0.0, 0.0, 0.01]])[
        : len(dims), : len(dims)
    ]
    return ExplorationDistribution(dims, np.ones(1), mean[None], cov[None])


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--seeds", help="family table: point-set seeds A-B (default: --seed only), e.g. 0-19"
    )
    ap.add_argument("--sizes", default="100,300,1000,2000", help="point counts of the family table")
    ap.add_argument("--instances", type=int, default=3, help="point sets per family table cell")
    ap.add_argument("--part", choices=("all", "tshix", "tsp"), default="all")
    ap.add_argument("--lkh-cache", help="JSON file keeping LKH's results (family table)")
    ap.add_argument("--only-lkh", action="store_true", help="only fill the LKH cache")
    add_markdown_option(ap)
    args = ap.parse_args(argv)
    markdown = checked_markdown(ap, args.markdown)
    if markdown is not None and args.only_lkh and args.part != "tshix":
        ap.exit(2, "error: --only-lkh makes no family table for --markdown: drop one of them\n")
    open_tour(np.random.default_rng(0).uniform(size=(20, 2)))  # compile the kernel first
    sizes, tables = [int(v) for v in args.sizes.split(",")], []
    if args.part != "tsp":
        tables += tshix_speed(args.repeats, args.seed)
    if args.part != "tshix":
        seeds = _seed_range(ap, args.seeds) if args.seeds else [args.seed]
        cells = families(seeds, sizes, args.instances, args.lkh_cache, args.only_lkh)
        if not args.only_lkh:
            tables.append(families_markdown(cells, sizes, args.instances * len(seeds)))
    append_table(ap, markdown, "\n\n".join(tables))


#: the (D, N) of the TSHIX table's rows that ``--markdown`` writes (all are printed): the
#: results page's table
MARKDOWN_SIZES = {(2, 100), (2, 300), (2, 500), (3, 300)}


def tshix_speed(repeats: int, seed: int) -> list[str]:
    """TSHIX planning time and tour length vs LKH; ergodic trajectories of the same length.
    Prints both tables as it goes; returns them as markdown (the TSHIX table's rows at
    :data:`MARKDOWN_SIZES`)."""
    print("TSHIX wall time (median of", repeats, "runs), tour length vs LKH (elkai, RUNS=1)")
    print(
        f"{'dims':>6} {'N':>4} {'TSHIX [ms]':>11} {'TSP ours [ms]':>14} {'LKH [ms]':>9} "
        f"{'ratio med':>9} {'ratio max':>9}"
    )
    rows, lengths = [], {}
    for dims in (("x", "y"), ("x", "y", "rz")):
        planner = TshixPlanner(_expl(dims), speed=0.01)
        for n in (100, 200, 300, 400, 500):
            row, tr = _tshix_row(planner, dims, n, repeats, seed)
            if (len(dims), n) in MARKDOWN_SIZES:
                rows.append(row)
            if n == 300:
                lengths[dims] = (tr, planner.length_scale)
    title = (
        "**TSHIX wall time (quasi-random sampling included) and tour length against LKH-3 "
        f"(elkai, RUNS=1)**; median of {repeats} runs"
    )
    head = ("D", "N", "TSHIX total", "our TSP", "LKH (elkai)", "our tour / LKH tour (median / max)")
    tables = [table(title, head, rows)]
    print("\nErgodic (SMC) trajectory of the TSHIX N=300 length")
    rows = [_ergodic_row(dims, tr, ls, repeats) for dims, (tr, ls) in lengths.items()]
    title = (
        "**Ergodic trajectory (spectral multiscale coverage, then optimisation at the length) of "
        "the TSHIX N = 300 length**"
    )
    opt = "`ergodic-opt` (5x the iterations): metric, time"
    head = ("D", "time", "ergodic metric (spectral start's; TSHIX's)", opt)
    return [*tables, table(title, head, rows)]


def _tshix_row(
    planner: TshixPlanner, dims: tuple[str, ...], n: int, repeats: int, seed: int
) -> tuple[list[str], SearchTrajectory]:
    """One size's medians (printed; returned as a markdown row) and the first run's plan."""
    w = metric_weights(dims, planner.length_scale)
    t_plan, t_ours, t_lkh, ratios, plans = [], [], [], [], []
    for r in range(repeats):
        rng = np.random.default_rng(seed + r)
        t0 = time.perf_counter()
        tr = planner.plan(n, rng)
        t_plan.append(time.perf_counter() - t0)
        plans.append(tr)
        t0 = time.perf_counter()
        ours = open_tour(tr.samples, weights=w, rng=np.random.default_rng(r))
        t_ours.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        ref = open_tour(tr.samples, weights=w, solver="lkh")
        t_lkh.append(time.perf_counter() - t0)
        ratios.append(ours.length / ref.length)
    plan, mine, lkh = (1e3 * float(np.median(v)) for v in (t_plan, t_ours, t_lkh))
    med, top = float(np.median(ratios)), float(np.max(ratios))
    print(f"{len(dims):>6} {n:>4} {plan:>11.1f} {mine:>14.1f} {lkh:>9.0f} {med:>9.4f} {top:>9.4f}")
    row = [str(len(dims)), str(n), f"{plan:.1f} ms", f"{mine:.1f} ms", f"{lkh:.0f} ms"]
    return [*row, f"{med:.3f} / {top:.3f}"], plans[0]


def _ergodic_row(dims: tuple[str, ...], tr: SearchTrajectory, ls: float, repeats: int) -> list[str]:
    """The default ergodic trajectory (spectral coverage, then optimisation at the length) of
    ``tr``'s length, its spectral start alone, and ``ergodic-opt`` (printed; markdown row)."""
    expl = _expl(dims)
    length = tr.path_length(ls)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        erg = ergodic_search(expl, speed=0.01, length=length)
        times.append(time.perf_counter() - t0)
    e_tshix = ergodic_metric(tr.states, expl, t=tr.t)
    t0 = time.perf_counter()
    opt = ergodic_search(expl, speed=0.01, length=length, iterations=1000, method="ergodic-opt")
    t_opt = time.perf_counter() - t0
    e_smc, e_erg, e_opt = (
        erg.meta["ergodic_metric_initial"],
        *(v.meta["ergodic_metric"] for v in (erg, opt)),
    )
    print(
        f"  D={len(dims)} length {length:.3f} m: {np.median(times):.3f} s wall; "
        f"ergodic metric: default {e_erg:.4f} (spectral start {e_smc:.4f}), TSHIX {e_tshix:.4f}; "
        f"ergodic-opt {e_opt:.4f} in {t_opt:.2f} s; lengths {erg.path_length(ls):.3f} m, "
        f"{opt.path_length(ls):.3f} m"
    )
    return [
        str(len(dims)),
        f"{np.median(times):.3f} s",
        f"{e_erg:.4f} ({e_smc:.4f}; {e_tshix:.4f})",
        f"{e_opt:.4f}, {t_opt:.1f} s",
    ]


def _points(family: str, n: int, rng: np.random.Generator) -> np.ndarray:
    """Points in a 40 mm square (m): uniform, Gaussian (10 mm) or 8 clusters (2 mm spread)."""
    if family == "uniform":
        return rng.uniform(-0.02, 0.02, (n, 2))
    if family == "gaussian":
        return rng.normal(0.0, 0.01, (n, 2))
    centres = rng.uniform(-0.02, 0.02, (8, 2))
    return centres[rng.integers(0, 8, n)] + rng.normal(0.0, 0.002, (n, 2))


def _lkh_cached(cache_file: str | None, key: str, pts: np.ndarray) -> tuple[float, float]:
    """LKH-3 length and CPU seconds of one instance, read from / added to ``cache_file``.

    LKH (RUNS=1) is deterministic and takes minutes at 2000 points: its results are kept in a
    JSON file (merged on write, so two runs may share it)."""
    cache = {}
    if cache_file and os.path.exists(cache_file):
        with open(cache_file) as f:
            cache = json.load(f)
    if key in cache:
        return tuple(cache[key])
    t0 = time.process_time()
    length = open_tour(pts, solver="lkh").length
    cpu = time.process_time() - t0
    if cache_file:
        if os.path.exists(cache_file):
            with open(cache_file) as f:
                cache = json.load(f)
        cache[key] = (length, cpu)
        tmp = cache_file + ".tmp"
        with open(tmp, "w") as f:
            json.dump(cache, f, indent=0)
        os.replace(tmp, cache_file)
    return length, cpu


#: a family table cell: our CPU seconds, LKH's CPU seconds, our length / LKH's, per instance
Cell = tuple[list[float], list[float], list[float]]
FAMILIES = {"uniform": "uniform", "gaussian": "Gaussian", "clustered": "clustered (8 clusters)"}


def _seed_range(ap: argparse.ArgumentParser, text: str) -> list[int]:
    """``A-B`` (or one seed) as the list of seeds; else one line and exit status 2."""
    lo, _, hi = text.partition("-")
    try:
        seeds = list(range(int(lo), int(hi or lo) + 1))
    except ValueError:
        seeds = []
    if not seeds:
        ap.exit(2, f"error: --seeds {text!r}: give A-B with A <= B, e.g. 0-19\n")
    return seeds


def families(
    seeds: list[int],
    sizes: list[int],
    instances: int = 3,
    lkh_cache: str | None = None,
    only_lkh: bool = False,
) -> dict[tuple[str, int], Cell]:
    """Open tours on uniform, Gaussian and clustered points: ours vs LKH-3 (elkai, RUNS=1).

    Per cell, ``instances`` seeded point sets per seed (seed ``(seed, i, n)``); prints the
    median and max of our length / LKH's, how many are over 1.01, and the medians of both CPU
    times (ours: the least of three calls on each instance, which a loaded machine disturbs
    least); returns the cells by (family, N)."""
    sets = instances * len(seeds)
    print(f"\nOpen tour on three point families ({sets} instances; CPU ms; length / LKH)")
    print(
        f"{'family':>10} {'N':>5} {'ours [ms]':>10} {'LKH [s]':>8} {'ratio med':>9} "
        f"{'ratio max':>9} {'> 1.01':>6}"
    )
    cells = {}
    for n in sizes:
        for family in FAMILIES:
            t_ours, t_lkh, ratios = cells[family, n] = [], [], []
            for seed, i in itertools.product(seeds, range(instances)):
                pts = _points(family, n, np.random.default_rng((seed, i, n)))
                ref, cpu = _lkh_cached(lkh_cache, f"{family}/{n}/{seed}/{i}", pts)
                t_lkh.append(cpu)
                if only_lkh:
                    continue
                cpus = []
                for _ in range(3):  # the same tour each time: the least CPU time of three
                    t0 = time.process_time()
                    ours = open_tour(pts)
                    cpus.append(time.process_time() - t0)
                t_ours.append(min(cpus))
                ratios.append(ours.length / ref)
            if only_lkh:
                print(f"{family:>10} {n:>5} {'':>10} {np.median(t_lkh):>8.1f}", flush=True)
                continue
            print(
                f"{family:>10} {n:>5} {1e3 * np.median(t_ours):>10.1f} "
                f"{np.median(t_lkh):>8.1f} {np.median(ratios):>9.4f} {np.max(ratios):>9.4f} "
                f"{sum(r > 1.01 for r in ratios):>6}",
                flush=True,
            )
    return cells


def _seconds(t: float) -> str:
    return f"{1e3 * t:.0f} ms" if t < 1 else f"{t:.1f} s"


def _lkh_range(medians: list[float]) -> str:
    """LKH's median CPU seconds over the families: one figure, or the range."""
    lo, hi = (f"{v:.1f}" if v < 10 else f"{v:.0f}" for v in (min(medians), max(medians)))
    return f"{lo} s" if lo == hi else f"{lo}-{hi} s"


def families_markdown(cells: dict[tuple[str, int], Cell], sizes: list[int], instances: int) -> str:
    """The family table: a row per family (ratio median (max), our CPU time), a column per
    N, and a last row of LKH's CPU time."""
    rows = []
    for family, label in FAMILIES.items():
        row = [label]
        for n in sizes:
            t_ours, _, ratios = cells[family, n]
            over = sum(r > 1.01 for r in ratios)
            spread = f" ({max(ratios):.4f}; {over} > 1.01)" if len(ratios) > 1 else ""
            row.append(f"{np.median(ratios):.4f}{spread}, {_seconds(float(np.median(t_ours)))}")
        rows.append(row)
    lkh = [_lkh_range([float(np.median(cells[f, n][1])) for f in FAMILIES]) for n in sizes]
    rows.append(["LKH-3 CPU (median)", *lkh])
    title = (
        f"**Open tour on three point families** ({instances} seeded instances per cell; ours / "
        "LKH-3 length, median (max; instances over 1.01); ours: CPU time, least of three calls, "
        "median over instances)"
    )
    head = ["points", *(f"N = {n}" if i == 0 else str(n) for i, n in enumerate(sizes))]
    return table(title, head, rows)


if __name__ == "__main__":
    main()
