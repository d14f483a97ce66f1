"""f_z smoothness at 100 Hz on both robots: issue 11's "contact that looks like a real sensor".

Usage: ``python benchmarks/sensor_smoothness.py [--seed 0] [--task peg2d] [--no-teacher]
[--slide 4.0] [--markdown FILE]``

Prints, for the floating tool and the FR3 (joint-torque estimate and wrist F/T), the f_z mean,
standard deviation and lag-1 autocorrelation of (1) the seeded blind teacher's demonstration
(1 s after its start to 1 s before its end; whole and median per straight pass) and (2) a
``--slide`` s straight slide pressed as the teacher presses; goal: std <= 0.5 N, lag-1 >= 0.9
(:mod:`teachfit.bench.sensor`). ``--markdown FILE`` appends the table (without the mean and
sample columns), headed with where it came from (``benchmarks/results/sensor.md`` feeds
BENCHMARKS.md).
"""

from __future__ import annotations

import argparse
from typing import Any

from teachfit.bench.sensor import (
    GOAL_LAG1,
    GOAL_STD,
    Smoothness,
    slide_smoothness,
    teacher_smoothness,
)
from teachfit.cli.script_markdown import add_markdown_option, append_table, checked_markdown, table

#: the recordings' robots: name, label, robot options, whether the teacher is recorded on it
ROBOTS: tuple[tuple[str, str, dict[str, Any], bool], ...] = (
    ("floating", "floating", {}, True),
    ("fr3", "fr3 (joint torques)", {}, True),
    ("fr3", "fr3 (wrist F/T)", {"sensor": "wrist-ft"}, False),
)


def _row(label: str, std: float, lag1: float, mean: str = "", n: str = "") -> list[str]:
    """A printed row (with the mean and sample count) printed now; the markdown row returned."""
    goal = "yes" if std <= GOAL_STD and lag1 >= GOAL_LAG1 else "no"
    print(f"| {label} | {mean} | {std:.3f} N | {lag1:.3f} | {n} | {goal} |", flush=True)
    return [label, f"{std:.3f} N", f"{lag1:.3f}", goal]


def _figures(label: str, s: Smoothness) -> list[str]:
    return _row(label, s.std, s.lag1, f"{s.mean:.2f} N", str(s.n))


def recordings(seed: int, task: str, slide: float, teacher: bool) -> list[list[str]]:
    """Each robot's teacher demonstration (whole, straight passes) and slide, printed as they
    finish; the markdown rows."""
    rows = []
    for robot, label, options, teaches in ROBOTS:
        if teacher and teaches:
            r = teacher_smoothness(robot, task, seed)
            rows.append(
                _figures(f"{label}, teacher demonstration ({r.duration:.1f} s), whole", r.whole)
            )
            passes = f"{robot}, same, median of {len(r.passes)} straight passes"
            rows.append(_row(passes, r.pass_std, r.pass_lag1))
        s = slide_smoothness(robot, task, seed, duration=slide, start_xy=(0.035, -0.024), **options)
        rows.append(_figures(f"{label}, {slide:g} s straight slide", s))
    return rows


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--task", default="peg2d")
    ap.add_argument("--no-teacher", action="store_true", help="only the short slides")
    ap.add_argument("--slide", type=float, default=4.0, help="the slides' length (s)")
    add_markdown_option(ap)
    args = ap.parse_args(argv)
    markdown = checked_markdown(ap, args.markdown)
    if not args.slide >= 0.05 or args.slide == float("inf"):
        ap.exit(2, f"error: --slide {args.slide}: give a slide of at least 0.05 s\n")
    print("| recording | f_z mean | f_z std | lag-1 | samples | goal met |")
    print("| --- | --- | --- | --- | --- | --- |")
    rows = recordings(args.seed, args.task, args.slide, not args.no_teacher)
    title = (
        f"**f_z at 100 Hz, seed {args.seed}, {args.task}** (goal: std <= {GOAL_STD} N and lag-1 "
        f"autocorrelation >= {GOAL_LAG1})"
    )
    append_table(ap, markdown, table(title, ("recording", "f_z std", "lag-1", "goal met"), rows))


if __name__ == "__main__":
    main()
