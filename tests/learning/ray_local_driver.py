"""The driver of ``test_ray_local_confined.py``, in a process of its own (the test kills it):
``python ray_local_driver.py STUDY_FILE``. A study of 1-s trials on a local Ray instance of one
CPU; prints ``stored N`` as each trial is stored."""

from __future__ import annotations

import sys
import time

from teachfit.learning import ParamDomain, ParamSpace, Study
from teachfit.learning.ray_runner import run_study_ray


def slow_bowl(p: dict[str, float]) -> float:
    """A bowl that takes 1 s (so that the run is still going when the test looks at it)."""
    time.sleep(1.0)
    return (p["a"] - 0.3) ** 2


def main() -> None:
    study = Study(
        sys.argv[1],
        task="puzzle",
        skill="peg-in-hole",
        space=ParamSpace({"a": ParamDomain(0.0, 1.0)}),
        method="lhs",
        options={"n": 1000},
    )
    run_study_ray(
        study,
        slow_bowl,
        1000,
        address="local",
        workers=1,
        on_trial=lambda rec: print(f"stored {rec.number + 1}", flush=True),
    )


if __name__ == "__main__":
    main()
