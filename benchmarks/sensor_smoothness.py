"""f_z smoothness at 100 Hz on both robots: issue 11's "contact that looks like a real sensor".

Usage: ``python benchmarks/sensor_smoothness.py [--seed 0] [--task peg2d] [--no-teacher]``

Prints, for the floating tool and the FR3 (joint-torque estimate and wrist F/T), the f_z mean,
standard deviation and lag-1 autocorrelation of (1) the seeded blind teacher's demonstration
(1 s after its start to 1 s before its end; whole and median per straight pass) and (2) a
4 s straight slide pressed as the teacher presses; goal: std <= 0.5 N, lag-1 >= 0.9
(:mod:`teachfit.bench.sensor`).
"""

from __future__ import annotations

import argparse

from teachfit.bench.sensor import Smoothness, slide_smoothness, teacher_smoothness

ROBOTS = (("floating", {}), ("fr3", {}), ("fr3", {"sensor": "wrist-ft"}))


def _row(label: str, s: Smoothness) -> str:
    goal = "yes" if s.meets_goal else "no"
    return f"| {label} | {s.mean:.2f} N | {s.std:.3f} N | {s.lag1:.3f} | {s.n} | {goal} |"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--task", default="peg2d")
    ap.add_argument("--no-teacher", action="store_true", help="only the short slides")
    args = ap.parse_args()
    print("| recording | f_z mean | f_z std | lag-1 | samples | goal met |")
    print("| --- | --- | --- | --- | --- | --- |")
    for robot, options in ROBOTS:
        name = robot + (f" ({options['sensor']})" if options else " (default sensor)")
        s = slide_smoothness(
            robot, args.task, args.seed, duration=4.0, start_xy=(0.035, -0.024), **options
        )
        print(_row(f"{name}, 4 s straight slide", s), flush=True)
    if args.no_teacher:
        return
    for robot in ("floating", "fr3"):
        r = teacher_smoothness(robot, args.task, args.seed)
        print(_row(f"{robot}, teacher demonstration ({r.duration:.1f} s), whole", r.whole))
        print(
            f"| {robot}, same, {len(r.passes)} straight passes (median) | | "
            f"{r.pass_std:.3f} N | {r.pass_lag1:.3f} | | |",
            flush=True,
        )


if __name__ == "__main__":
    main()
