"""Ehlers et al.'s search experiments reproduced in simulation, beside the paper's numbers.

- Table I: one demonstration; 30 starts in a 3 cm circle halfway between the demonstration's
  start and the hole; TSHIX (300 points, a new trajectory per start) vs. one ergodic trajectory
  of about the mean TSHIX length, both with the GMR feed-forward. We add TSHIX with Ehlers et al.'s
  i.i.d. sampling beside our default quasi-random sampling.
- Table II: one start, 20 TSHIX trajectories per N = 100 ... 500: success and planning time.
- Ablation: the same without the feed-forward, N = 100, 200, 400.
- Table III: ``socket3d`` (x, y, rz), 15 starts in the socket's upper half, 600 points: random
  walk, spiral, TSHIX from one and from two demonstrations (started at opposite ends; with
  Ehlers et al.'s full covariance, with per-DOF variances only, and with `learn search`'s
  default: the chosen covariance made even in rz) and the 3D ergodic trajectory (which the
  paper could not produce).

Every execution is a :class:`~teachfit.bench.search_jobs.SearchJob` run in worker processes.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from typing import TypedDict, Unpack

import numpy as np

from teachfit.bench.search_jobs import (
    JobResult,
    SearchJob,
    model_json,
    planned_lengths,
    pose_tuple,
    run_jobs,
)
from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import Pose
from teachfit.demonstrations.dataset import Demonstration
from teachfit.execution.batch import episode_seed
from teachfit.execution.teacher import BlindTeacher, TeacherStyle
from teachfit.execution.teacher_cache import cache_key, cached
from teachfit.metrics.stats import SuccessSummary, summarize
from teachfit.models.search_model import SearchModel
from teachfit.tasks.geometry.socket3d import Socket3D
from teachfit.tasks.registry import get_task

#: the paper's real-robot results (successes, trials)
PAPER_TABLE1 = {"tshix": (25, 30), "ergodic": (20, 30)}
PAPER_TABLE2 = {100: (6, 20), 200: (12, 20), 300: (17, 20), 400: (17, 20), 500: (17, 20)}
#: the paper's trajectory-creation CPU time per N (s, Core2 Quad Q9400, MATLAB GA TSP)
PAPER_TABLE2_CPU = {100: 13.8, 200: 34.1, 300: 61.9, 400: 94.3, 500: 135.6}
PAPER_ABLATION = {100: (2, 20), 200: (7, 20), 400: (13, 20)}
PAPER_TABLE3 = {"random-walk": (0, 15), "tshix-1demo": (3, 15), "tshix-2demo": (10, 15)}

Progress = Callable[[], None] | None


@dataclass(frozen=True)
class Row:
    """One line of a table: ours beside the paper's ``(successes, trials)`` (None: no figure).

    ``plan_ms`` is the median planning wall time; ``length`` the mean path length (m, rz
    unweighted); ``ergodic`` the mean ergodic metric of the executed plans; ``outcomes`` each
    job's success in the order of its seeds (rows run on the same seeds pair up).
    """

    method: str
    ours: SuccessSummary
    paper: tuple[int, int] | None
    plan_ms: float
    length: float
    ergodic: float
    paper_cpu_s: float | None = None
    outcomes: tuple[bool, ...] = ()


def _row(
    method: str,
    results: Sequence[JobResult],
    paper: tuple[int, int] | None,
    paper_cpu_s: float | None = None,
) -> Row:
    s = summarize([r.success for r in results], [r.time_to_insertion for r in results])
    return Row(
        method,
        s,
        paper,
        1e3 * float(np.median([r.plan_s for r in results])),
        float(np.mean([r.path_length for r in results])),
        float(np.mean([r.ergodic_metric for r in results])),
        paper_cpu_s,
        tuple(bool(r.success) for r in results),
    )


#: the robot every table runs on (set by :func:`use_robot`; one name, read by the job builders)
ROBOT = ["floating"]


def use_robot(name: str) -> None:
    """Run the following tables on robot ``name`` (a registry name, e.g. ``"fr3"``)."""
    from teachfit.robot.registry import ROBOTS

    if name not in ROBOTS:
        raise TeachfitError(f"unknown robot {name!r}; known robots: {sorted(ROBOTS)}")
    ROBOT[0] = name


class JobOptions(TypedDict, total=False):
    """The optional :class:`SearchJob` fields :func:`_jobs` passes on (same names)."""

    feedforward: bool
    length: float | None
    sampling: str
    robot_seed: int
    passes: int
    robot: str


def _jobs(
    task: str,
    overrides: dict[str, float],
    model: SearchModel,
    starts: Sequence[Pose],
    method: str,
    n_points: int,
    seeds: Sequence[int],
    **kw: Unpack[JobOptions],
) -> list[SearchJob]:
    doc = model_json(model)
    ov = tuple(sorted(overrides.items()))
    kw.setdefault("robot", ROBOT[0])
    return [
        SearchJob(task, ov, doc, pose_tuple(p), method, n_points, s, **kw)
        for p, s in zip(starts, seeds, strict=True)
    ]


def _peg_setup(seed: int, clearance: float) -> tuple[dict[str, float], Demonstration, SearchModel]:
    demo, model = _peg_demo(seed, clearance, ROBOT[0])
    return {"clearance": clearance}, demo, model


@cache
def _peg_demo(seed: int, clearance: float, robot: str) -> tuple[Demonstration, SearchModel]:
    """The seeded teacher's demonstration and its model (recorded once per process: Tables I,
    II and the ablation share them; both are immutable)."""
    task = get_task("peg2d", clearance=clearance)
    demos, _ = BlindTeacher(task, seed=seed, robot=robot).record(1)
    return demos[0], SearchModel.fit(demos, task.name)


#: Table I's rows, in table order
TABLE1_METHODS = ("tshix", "tshix-iid", "ergodic")
#: Table III's rows, in table order
TABLE3_METHODS = (
    "random-walk",
    "spiral",
    "tshix-1demo",
    "tshix-2demo",
    "tshix-2demo-diag",
    "tshix-2demo-auto",
    "ergodic-3d-2demo",
)


def chosen_methods(
    methods: Sequence[str] | None, available: Sequence[str], table: str
) -> tuple[str, ...]:
    """The rows of ``table`` to run: ``methods`` in table order (None: all ``available``)."""
    if methods is None:
        return tuple(available)
    unknown = [m for m in methods if m not in available]
    if unknown or not methods:
        raise TeachfitError(
            f"Table {table} has no method {unknown[0] if unknown else '(none given)'!r}; "
            f"available: {', '.join(available)}"
        )
    return tuple(m for m in available if m in methods)


def _planned_tshix(model: SearchModel, n_points: int, seeds: Sequence[int]) -> tuple[float, float]:
    """Mean weighted (rz at the planner's scale) and x-y lengths (m) of the TSHIX paths that
    jobs with ``seeds`` plan: what the ergodic and random-walk rows are sized by (planning only,
    the same paths the TSHIX jobs execute)."""
    lengths = [planned_lengths(model, "tshix", n_points, s) for s in seeds]
    return float(np.mean([w for _, w in lengths])), float(np.mean([xy for xy, _ in lengths]))


def _run_rows(
    jobs: dict[str, list[SearchJob]],
    paper: Mapping[str, tuple[int, int] | None],
    workers: int | None,
    progress: Progress,
) -> list[Row]:
    """Run every row's jobs in one parallel batch; the rows in ``jobs``' order."""
    flat = [j for js in jobs.values() for j in js]
    res = iter(run_jobs(flat, workers, progress))
    return [_row(name, [next(res) for _ in js], paper[name]) for name, js in jobs.items()]


def table1(
    seed: int = 0,
    n_starts: int = 30,
    n_points: int = 300,
    clearance: float = 0.0005,
    workers: int | None = None,
    progress: Progress = None,
    methods: Sequence[str] | None = None,
) -> list[Row]:
    """Table I's protocol; rows ``tshix``, ``tshix-iid`` and ``ergodic`` (or ``methods`` of
    :data:`TABLE1_METHODS`) on the same starts."""
    chosen = chosen_methods(methods, TABLE1_METHODS, "I")
    overrides, demo, model = _peg_setup(seed, clearance)
    task = get_task("peg2d", **overrides)
    rng = np.random.default_rng(seed + 1)
    starts = task.protocol.protocol_starts("table1", n_starts, rng, demo.start_pose)
    seeds = [episode_seed(seed, i) for i in range(n_starts)]
    job = {
        "tshix": lambda: _jobs("peg2d", overrides, model, starts, "tshix", n_points, seeds),
        "tshix-iid": lambda: _jobs(
            "peg2d", overrides, model, starts, "tshix", n_points, seeds, sampling="random"
        ),
        "ergodic": lambda: _jobs(
            "peg2d",
            overrides,
            model,
            starts,
            "ergodic",
            n_points,
            seeds,
            length=_planned_tshix(model, n_points, seeds)[0],
        ),
    }
    paper = {"tshix": PAPER_TABLE1["tshix"], "tshix-iid": PAPER_TABLE1["tshix"]}
    paper["ergodic"] = PAPER_TABLE1["ergodic"]
    return _run_rows({m: job[m]() for m in chosen}, paper, workers, progress)


def table2(
    seed: int = 0,
    sizes: Sequence[int] = (100, 200, 300, 400, 500),
    n_traj: int = 20,
    ablation: Sequence[int] = (100, 200, 400),
    clearance: float = 0.0005,
    workers: int | None = None,
    progress: Progress = None,
) -> tuple[list[Row], list[Row]]:
    """Table II (success and planning time per N) and the feed-forward ablation.

    Returns ``(table2_rows, ablation_rows)``; ablation rows are named ``N=... no-ff``, each
    beside the paper's figure, and are compared with Table II's rows at the same N.
    """
    overrides, demo, model = _peg_setup(seed, clearance)
    task = get_task("peg2d", **overrides)
    start = task.protocol.protocol_starts(
        "table2", 1, np.random.default_rng(seed), demo.start_pose
    )[0]
    starts = [start] * n_traj
    jobs: list[SearchJob] = []
    for n in sizes:
        seeds = [episode_seed(seed, n * 100 + k) for k in range(n_traj)]
        jobs += _jobs("peg2d", overrides, model, starts, "tshix", n, seeds)
    for n in ablation:
        seeds = [episode_seed(seed, n * 100 + k) for k in range(n_traj)]
        jobs += _jobs("peg2d", overrides, model, starts, "tshix", n, seeds, feedforward=False)
    res = run_jobs(jobs, workers, progress)
    rows, abl = [], []
    for i, n in enumerate(sizes):
        chunk = res[i * n_traj : (i + 1) * n_traj]
        rows.append(_row(f"N={n}", chunk, PAPER_TABLE2.get(n), PAPER_TABLE2_CPU.get(n)))
    off = len(sizes) * n_traj
    for i, n in enumerate(ablation):
        chunk = res[off + i * n_traj : off + (i + 1) * n_traj]
        abl.append(_row(f"N={n} no-ff", chunk, PAPER_ABLATION.get(n)))
    return rows, abl


def _socket_demos(task: object, seed: int) -> list[Demonstration]:
    """Two worst-case teacher demonstrations started at opposite ends of the socket's upper half
    (:func:`record_socket_demos`); raises if one end failed six times."""
    demos, discarded = record_socket_demos(task, seed)
    if len(demos) < 2:
        raise TeachfitError(
            f"the teacher failed six times from one end of the socket ({discarded[-1]})"
        )
    return demos


def record_socket_demos(task: object, seed: int) -> tuple[list[Demonstration], list[str]]:
    """Two worst-case teacher demonstrations started at opposite ends of the socket's upper
    half, and the reasons of the discarded attempts (up to six per end; fewer than two
    demonstrations when an end failed six times).

    Opposite ends in position (left and right of the upper half, against the wall) and in yaw
    (turned by 60-100 % of ``start_rz`` one way, then the other), so that together they span
    the start variability as Ehlers et al. 2019 asks of demonstrations. Cached like the teacher's
    own recordings (:mod:`teachfit.execution.teacher_cache`).
    """
    key = cache_key(
        task=task, style=TeacherStyle(), seed=seed, robot=ROBOT[0], n=2, limit=6, kind="socket"
    )
    return cached(key, lambda: _record_socket_demos(task, seed))


def _record_socket_demos(task: object, seed: int) -> tuple[list[Demonstration], list[str]]:
    if not isinstance(task, Socket3D):
        raise TeachfitError(f"socket demonstrations need the socket3d task, got {task!r}")
    rng = np.random.default_rng(seed)
    dist = task.play - task.params.start_wall_gap
    teacher = BlindTeacher(task, seed=seed, robot=ROBOT[0])
    demos: list[Demonstration] = []
    discarded: list[str] = []
    rz_max = task.params.start_rz
    for (lo, hi), sign in (((0.05, 0.25), 1.0), ((0.75, 0.95), -1.0)):
        for _attempt in range(6):
            ang = np.pi * rng.uniform(lo, hi)
            rz = sign * rng.uniform(0.6 * rz_max, rz_max)  # worst case: far from aligned
            start = task.contact_pose(dist * np.array([np.cos(ang), np.sin(ang)]), rz)
            demo, why = teacher.demonstrate(start)
            if demo is not None:
                demos.append(demo)
                break
            discarded.append(why)
        else:
            return demos, discarded
    return demos, discarded


def table3(
    seed: int = 0,
    n_starts: int = 15,
    n_points: int = 600,
    workers: int | None = None,
    progress: Progress = None,
    methods: Sequence[str] | None = None,
) -> list[Row]:
    """Table III's protocol on ``socket3d``; one row per method of :data:`TABLE3_METHODS` (or
    ``methods`` of them), same starts for all."""
    chosen = chosen_methods(methods, TABLE3_METHODS, "III")
    task = get_task("socket3d")
    demos = _socket_demos(task, seed)
    # Ehlers et al.'s rows keep its full covariance and no mirror image; `learn search`'s default
    # (the -auto row) chooses the covariance by held-out likelihood (per-DOF variances on these
    # two demonstrations) and makes p_e even in rz (`auto_mirror`)
    one = SearchModel.fit(demos[:1], task.name, covariance="full", mirror=())
    two = SearchModel.fit(demos, task.name, covariance="full", mirror=())
    two_diag = SearchModel.fit(demos, task.name, covariance="diag", mirror=())
    two_auto = SearchModel.fit(demos, task.name)
    starts = task.protocol.protocol_starts("table3", n_starts, np.random.default_rng(seed + 1))
    seeds = [episode_seed(seed, i) for i in range(n_starts)]

    planned = cache(lambda: _planned_tshix(two, n_points, seeds))  # planned once for both rows

    def sized(method: str) -> list[SearchJob]:
        """The random walk of the mean TSHIX (2 demos) x-y length, or the ergodic trajectory
        of its weighted length."""
        length, xy = planned()
        if method == "random-walk":
            steps = max(1, int(xy / 0.003))  # random-walk moves average 3 mm: equal x-y length
            return _jobs("socket3d", {}, two, starts, "random-walk", steps, seeds)
        return _jobs("socket3d", {}, two, starts, "ergodic", n_points, seeds, length=length)

    job = {
        "random-walk": lambda: sized("random-walk"),
        "spiral": lambda: _jobs("socket3d", {}, two, starts, "spiral", n_points, seeds),
        "tshix-1demo": lambda: _jobs("socket3d", {}, one, starts, "tshix", n_points, seeds),
        "tshix-2demo": lambda: _jobs("socket3d", {}, two, starts, "tshix", n_points, seeds),
        "tshix-2demo-diag": lambda: _jobs(
            "socket3d", {}, two_diag, starts, "tshix", n_points, seeds
        ),
        "tshix-2demo-auto": lambda: _jobs(
            "socket3d", {}, two_auto, starts, "tshix", n_points, seeds
        ),
        "ergodic-3d-2demo": lambda: sized("ergodic"),
    }
    paper = {m: PAPER_TABLE3.get(m) for m in TABLE3_METHODS}
    return _run_rows({m: job[m]() for m in chosen}, paper, workers, progress)
