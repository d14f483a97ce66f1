"""The driver side of ``test_ray_runner.py``, in a process of its own: Ray reads its token
settings when imported, so a driver needs the cluster's token in its environment from the
start. ``python ray_driver.py ADDRESS DIR``; prints what the test checks."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import ray
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.learning import ParamDomain, ParamSpace, Study, TrialResult
from teachfit.learning.ray_runner import run_study_ray


def where(p: dict[str, float]) -> TrialResult:
    """A bowl that tells which node ran it (first 32 bits of the node id) and lasts 1 s."""
    time.sleep(1.0)
    node = int(ray.get_runtime_context().get_node_id()[:8], 16)
    return TrialResult((p["a"] - 0.3) ** 2, True, {"node": float(node)})


def main() -> None:
    address, out = sys.argv[1], Path(sys.argv[2])
    ray.init(address=address, include_dashboard=False, log_to_driver=False)
    deadline = time.monotonic() + 120
    while (alive := sum(nd["Alive"] for nd in ray.nodes())) < 3 and time.monotonic() < deadline:
        time.sleep(0.5)
    ray.shutdown()
    print(f"nodes alive: {alive}", flush=True)

    space = ParamSpace({"a": ParamDomain(0.0, 1.0)})
    study = Study(
        out / "nodes.db",
        task="puzzle",
        skill="peg-in-hole",
        space=space,
        method="lhs",
        options={"n": 6},
    )
    rep = run_study_ray(study, where, 6, address=address, workers=3)
    trials = study.trials()
    print(
        f"trials: finished {rep.finished} stored {len(trials)} "
        f"unique {len({t.key for t in trials})} nodes {len({t.info['node'] for t in trials})} "
        f"connected-after {ray.is_initialized()}",
        flush=True,
    )
    runner = CliRunner()
    res = runner.invoke(
        app,
        ["learn", "skill", "--task", "puzzle", "--method", "lhs", "--starts", "1"]
        + ["--trials", "3", "--study", str(out / "skill.db"), "--ray", address],
    )
    print(f"learn skill exit {res.exit_code}\n{res.output}", flush=True)
    res = runner.invoke(
        app,
        ["bench", "learning", "--scaling", "--ray", address, "--tasks", "puzzle"]
        + ["--scaling-workers", "1,2", "--scaling-trials", "1", "--starts", "1"],
    )
    print(f"bench scaling exit {res.exit_code}\n{res.output}", flush=True)


if __name__ == "__main__":
    main()
