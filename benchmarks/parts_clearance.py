"""The parts suite's simulated clearance floor, measured: the clearance the simulation lets a
peg feel at an ISO 286 H7/g6 fit's clearances and at the suite's 0.2 mm.

Usage: ``python benchmarks/parts_clearance.py [--parts round8-sharp-through,...]
[--markdown FILE]``

Per suite part (:mod:`teachfit.tasks.mesh.suite`) and diametral clearance (H7/g6's smallest
and largest at the part's nominal size, and :data:`~teachfit.tasks.mesh.suite.SIM_CLEARANCE`):
the geometric clearance per side, and the clearance *felt* per side: half the x travel of the
peg 3 mm deep in its hole, free in x and y, pushed along +x then -x with 5 N and 20 N
(:func:`round_contact.felt_clearance`; soft contact lets it sink into the wall). Where the
sinking is as large as the clearance itself, the simulation does not resolve the fit: the
ratio felt / geometric says by how much. ``--markdown FILE`` appends the table with its
provenance header (:func:`teachfit.cli.common.append_markdown`).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # round_contact, a sibling script

from round_contact import felt_clearance  # noqa: E402

from teachfit.cli.script_markdown import (  # noqa: E402
    add_markdown_option,
    append_table,
    checked_markdown,
    table,
)
from teachfit.tasks.mesh import suite  # noqa: E402
from teachfit.tasks.registry import load_task  # noqa: E402

HEAD = ("part", "fit", "clearance per side", "felt at 5 N", "felt at 20 N", "felt / geometric")
FORCES = (5.0, 20.0)  # N


def rows_of(name: str, folder: Path) -> list[list[str]]:
    """One row per clearance of part ``name`` (its files written under ``folder``)."""
    part = suite.PARTS[name]
    lo, hi = suite.iso_clearance(part.width)
    out = []
    for label, c in (("H7/g6 smallest", lo), ("H7/g6 largest", hi), ("suite", suite.SIM_CLEARANCE)):
        path = suite.write_part(part.at_clearance(c), folder / f"{name}-{c:g}")
        task = load_task(str(path))
        felt = [felt_clearance(task, force=f) * 1e6 for f in FORCES]
        side = c / 2 * 1e3  # um
        ratio = f"{felt[0] / side:.2f}-{felt[1] / side:.2f}"
        cells = [f"{side:.1f} um", f"{felt[0]:.1f} um", f"{felt[1]:.1f} um", ratio]
        out.append([name, f"{label} ({c * 1e3:g} um)", *cells])
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--parts", default="round8-sharp-through,rect12x8-sharp-through")
    add_markdown_option(ap)
    args = ap.parse_args(argv)
    markdown = checked_markdown(ap, args.markdown)
    names = [n.strip() for n in args.parts.split(",") if n.strip()]
    if not names or any(n not in suite.PARTS for n in names):
        ap.exit(2, f"error: --parts: choose from {', '.join(suite.PARTS)}\n")
    with tempfile.TemporaryDirectory() as tmp:
        rows = [r for n in names for r in rows_of(n, Path(tmp))]
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(HEAD)]
    for line in [list(HEAD), *rows]:
        print("  ".join(c.rjust(w) for c, w in zip(line, widths, strict=True)))
    title = "**Parts suite: the clearance the simulation lets a peg feel** (3 mm deep)"
    append_table(ap, markdown, table(title, HEAD, rows))


if __name__ == "__main__":
    main()
