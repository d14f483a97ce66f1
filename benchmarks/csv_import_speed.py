"""Speed of the CSV import of a robot log, against ``numpy.loadtxt`` of the same file.

Usage: ``python benchmarks/csv_import_speed.py [--rows 10000] [--repeats 5] [--seed 0]
[--markdown FILE]``

Writes a seeded log of ``--rows`` rows in the layout of ``examples/robot_log.csv`` (time,
position, quaternion, wrench) to a temporary folder, then times ``import_csv`` (parsing,
validation, unit and frame handling) and, as the baseline measured in the same run, a bare
``numpy.loadtxt`` of the same file. Figures are the fastest of ``--repeats`` runs (wall clock,
``time.perf_counter``); the ratio compares across machines. ``--markdown FILE`` appends the
table, headed with where it came from.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from teachfit.cli.script_markdown import add_markdown_option, append_table, checked_markdown, table
from teachfit.demonstrations.csv_import import ColumnMap, import_csv
from teachfit.demonstrations.importing import ImportOptions

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _fastest(fn: Callable[[], object], repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def write_log(path: Path, rows: int, seed: int) -> Path:
    """A seeded log of ``rows`` rows with the example log's first 14 columns."""
    rng = np.random.default_rng(seed)
    t = 1.7e9 + np.arange(rows) * 0.001
    q = rng.normal(size=(rows, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    table = np.column_stack([t, rng.normal(size=(rows, 3)), q, rng.normal(size=(rows, 6))])
    header = ",".join((EXAMPLES / "robot_log.csv").read_text().splitlines()[0].split(",")[:14])
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.9f")
    return path


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--rows", type=int, default=10_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    add_markdown_option(ap)
    args = ap.parse_args(argv)
    markdown = checked_markdown(ap, args.markdown)
    # the example's map without its text column (the marker): the seeded log is numbers only
    columns = dataclasses.replace(ColumnMap.from_toml(EXAMPLES / "columns.toml"), marker=None)
    with tempfile.TemporaryDirectory() as tmp:
        path = write_log(Path(tmp) / "log.csv", args.rows, args.seed)
        # random poses and wrenches fail the plausibility checks: they run, their findings are
        # accepted (noted), as with --accept-implausible
        every = ImportOptions(accept=frozenset({"all"}))
        read = functools.partial(import_csv, path, columns, task="peg2d", options=every)
        t_import = _fastest(read, args.repeats)
        t_base = _fastest(lambda: np.loadtxt(path, delimiter=",", skiprows=1), args.repeats)
    print(f"CSV import of {args.rows} rows (fastest of {args.repeats})")
    print(f"  import_csv     {1e3 * t_import:8.1f} ms  {args.rows / t_import:10.0f} rows/s")
    print(f"  numpy.loadtxt  {1e3 * t_base:8.1f} ms  {args.rows / t_base:10.0f} rows/s (baseline)")
    print(f"  ratio import_csv / loadtxt: {t_import / t_base:.2f}x")
    rows = [
        (name, f"{1e3 * t:.1f} ms", f"{args.rows / t:,.0f}")
        for name, t in (("`import_csv`", t_import), ("`numpy.loadtxt` (baseline)", t_base))
    ]
    rows.append(("ratio import_csv / loadtxt", f"{t_import / t_base:.2f}x", ""))
    title = f"**CSV import of {args.rows} rows** (fastest of {args.repeats}, seed {args.seed})"
    append_table(ap, markdown, table(title, ("reader", "time", "rows/s"), rows))


if __name__ == "__main__":
    main()
