"""Execute learned search trajectories (Ehlers et al. 2019): search frame -> world set-points + GMR
feed-forward -> impedance runner, and the batch protocols used by the CLI and benchmarks.

The search frame has its origin at the start pose; its axes are the world's (positions are
only translated) and ``rz`` adds to the start's yaw, as in Ehlers et al. 2019 where each
demonstration is translated so that its first pose is the origin.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

import numpy as np

from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import Pose, quat_from_rz
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.execution.batch import episode_rng
from teachfit.execution.engine import ExecutionResult
from teachfit.execution.follow import run_trajectory
from teachfit.models.search_model import SearchModel
from teachfit.robot.interface import Robot
from teachfit.skills.fit_context import fit_of, search_tilt_context
from teachfit.skills.follow import FollowConfig
from teachfit.skills.follower import TRACK_FEEL
from teachfit.skills.tilt import TiltConfig, rim_lead, tilted_drop, wedge_lag
from teachfit.tasks.base import Task
from teachfit.trajectories import SearchTrajectory, TshixPlanner
from teachfit.trajectories.baselines import archimedean_spiral, random_walk
from teachfit.trajectories.ergodic_opt import ergodic_search

METHODS = ("tshix", "ergodic", "ergodic-opt", "spiral", "random-walk")
_WRENCH_INDEX = {"x": 0, "y": 1, "z": 2, "rz": 5}
#: m past the deepest a tilted part sinks into the hole that means it left the top instead
#: (the tilt gives under the contact torque; the set-point leads the sinking part)
OFF_MARGIN = 0.002
#: s over which a fit task's tilted search turns from upright to its tilt (see
#: :class:`~teachfit.skills.tilt.TiltConfig`; the joined skill's blend, ``TILT_BLEND``)
FIT_TILT_RAMP = 0.5


def search_setpoints(
    traj: SearchTrajectory,
    task: Task,
    start: Pose,
    model: SearchModel | None = None,
    *,
    friction_floor: float = 0.0,
) -> SetpointTrajectory:
    """World set-points for a search trajectory started at ``start``.

    With ``model``, the feed-forward wrench is the GMR conditional mean of the action given the
    planned step (Ehlers et al. 2019, Sec. III-C), mapped onto the searched wrench components; its
    x-y force is projected onto the step's x-y direction, never below ``friction_floor`` (N)
    while moving (:func:`along_motion`).
    """
    states = np.asarray(traj.states, dtype=float)
    dims = tuple(traj.dims)
    if tuple(task.search_dims) != dims:
        raise TeachfitError(
            f"trajectory dims {dims} do not match task {task.name} {task.search_dims}"
        )
    n = states.shape[0]
    pos = np.tile(np.array([start.pos[0], start.pos[1], task.surface_z]), (n, 1))
    for j, d in enumerate(dims):
        if d in ("x", "y", "z"):
            pos[:, "xyz".index(d)] += states[:, j]
    rz = start.rz + (states[:, dims.index("rz")] if "rz" in dims else 0.0)
    quat = quat_from_rz(np.broadcast_to(rz, (n,))) if "rz" in dims else np.tile(start.quat, (n, 1))
    ff = np.zeros((n, 6))
    if model is not None and model.dynamics is not None:
        gmr = model.feedforward_along(traj.t, states)
        actions = along_motion(gmr, traj.t, states, dims, floor=friction_floor)
        for j, d in enumerate(dims):
            ff[:, _WRENCH_INDEX[d]] = actions[:, j]
    return SetpointTrajectory(traj.t, pos, quat, ff, name=traj.method)


def along_motion(
    actions: np.ndarray,
    t: np.ndarray,
    states: np.ndarray,
    dims: tuple[str, ...],
    floor: float = 0.0,
) -> np.ndarray:
    """The feed-forward ``actions`` (T, D; N, N·m) with their x-y force replaced by its part
    along the planned x-y motion of ``states`` at ``t``, never backwards and, while moving,
    never below ``floor`` (N; none at rest).

    Why: the force that keeps a sliding part on its path pushes along the motion (it meets
    friction); a component across it only drags the part off the path. A one-component GMR
    is a linear map of the step, and on a stick-slip demonstration (friction 0.8, Ø 8 mm
    peg2d) it learned ``(4.2, 0.4) N`` for a step along +y: the part then slid along +x,
    4 mm off a tour that crossed the hole. On the default cell the across part is <= 0.2 N.
    ``floor`` (the sliding friction, :func:`friction_floor`): with less, the spring pulls the
    rest and the part trails its set-point; at a turn of the tour that lag becomes an offset
    across the motion, where the follower is soft, and the part cuts the corner (Ø 12 mm,
    0.2 mm, μ 0.5: tours 0.8-1.2 mm from the axis passed by at 1.6-1.9 mm, outside the
    1.6 mm where the chamfers catch it).
    """
    lin = [j for j, d in enumerate(dims) if d in ("x", "y")]
    if len(lin) != 2:
        return actions
    out = np.array(actions, dtype=float)
    vel = np.gradient(np.asarray(states, float)[:, lin], np.asarray(t, float), axis=0)
    speed = np.linalg.norm(vel, axis=1)
    u = np.divide(vel, speed[:, None], out=np.zeros_like(vel), where=speed[:, None] > 1e-9)
    push = np.clip(np.sum(out[:, lin] * u, axis=1), 0.0, None)
    push = np.where(speed > 1e-9, np.maximum(push, floor), 0.0)
    out[:, lin] = push[:, None] * u
    return out


@dataclass(frozen=True)
class SearchRun:
    """One executed search: the engine's result, the planned trajectory, its set-points."""

    result: ExecutionResult
    trajectory: SearchTrajectory
    setpoints: SetpointTrajectory


#: most TSHIX samples / random-walk steps per pass: a plan through more takes minutes and GBs
MAX_POINTS = 10_000


def plan_search(
    model: SearchModel,
    method: str,
    n_points: int,
    rng: np.random.Generator,
    *,
    length: float | None = None,
    sampling: str = "qmc",
    passes: int = 1,
) -> SearchTrajectory:
    """A search trajectory in the search frame by ``method`` (see :data:`METHODS`).

    ``n_points``: TSHIX samples, or random-walk steps; an ergodic trajectory is as long as
    ``length`` (m, rz weighted by the planner's length scale) or as a TSHIX pass through
    ``n_points`` samples: spectral coverage, then trajectory optimisation at that length
    (:func:`~teachfit.trajectories.ergodic_opt.ergodic_search`; ``"ergodic-opt"`` with five
    times the optimiser's iterations). ``sampling``
    is TSHIX's sampler (``"qmc"`` or Ehlers et al.'s i.i.d. ``"random"``). The baselines span the
    exploration distribution's 2-sigma radius (and, for rz, its 2-sigma rz range).

    ``passes > 1`` (TSHIX only) appends re-sampled passes of ``n_points`` fresh samples, each
    starting where the previous one ends (Ehlers et al.'s re-sampling): the runner stops at
    insertion, so a pass is only executed when every pass before it failed.
    """
    _check_plan(method, n_points, passes)
    if method == "tshix":
        planner = TshixPlanner.from_model(model, sampling=sampling)
        traj = planner.plan(n_points, rng)
        for _ in range(passes - 1):
            traj = planner.extend(traj, n_points, rng)
        return traj
    if method in ("ergodic", "ergodic-opt"):
        return _plan_ergodic(model, method, n_points, rng, length, sampling)
    return _plan_baseline(model, method, n_points, rng)


def _check_plan(method: str, n_points: int, passes: int) -> None:
    """Refuse a number of points or passes :func:`plan_search` cannot plan."""
    if not 0 < n_points <= MAX_POINTS:
        raise TeachfitError(
            f"number of points must be 1 ... {MAX_POINTS} (Ehlers et al. use 300-600), "
            f"got {n_points}"
        )
    if passes < 1 or (passes > 1 and method != "tshix"):
        raise TeachfitError(f"passes must be 1, or >= 1 for tshix; got {passes} for {method}")


def _plan_ergodic(
    model: SearchModel,
    method: str,
    n_points: int,
    rng: np.random.Generator,
    length: float | None,
    sampling: str,
) -> SearchTrajectory:
    """An ergodic trajectory of ``length`` (by default a TSHIX pass's through ``n_points``
    samples), by :func:`~teachfit.trajectories.ergodic_opt.ergodic_search`."""
    if length is None:
        planner = TshixPlanner.from_model(model, sampling=sampling)
        length = planner.plan(n_points, rng).path_length(cast(float, planner.length_scale))
    # ergodic-opt: the same optimisation, five times the iterations
    return ergodic_search(
        model.exploration,
        speed=model.speed,
        length=length,
        angular_speed=model.angular_speed,
        start=np.zeros(len(model.dims)),
        iterations=200 if method == "ergodic" else 1000,
        method=method,
    )


def _plan_baseline(
    model: SearchModel, method: str, n_points: int, rng: np.random.Generator
) -> SearchTrajectory:
    """A spiral or a random walk over the exploration distribution's 2-sigma radius (and
    2-sigma rz range); any other ``method`` is refused."""
    dims = model.dims
    ex = model.exploration
    var = np.diag(ex.cov)
    lin = [i for i, d in enumerate(dims) if d != "rz"]
    radius = float(np.linalg.norm(ex.mean[lin]) + 2.0 * np.sqrt(var[lin].max()))
    rz_sd = float(np.sqrt(var[dims.index("rz")])) if "rz" in dims else 0.0
    if method == "spiral":
        return archimedean_spiral(
            dims,
            pitch=0.002,
            radius=radius,
            speed=model.speed,
            rz_amplitude=2.0 * rz_sd,
            angular_speed=model.angular_speed,
        )
    if method == "random-walk":
        return random_walk(
            dims,
            rng,
            n_steps=n_points,
            step_max=0.004,
            radius=radius,
            speed=model.speed,
            rz_step_max=rz_sd,
            rz_radius=2.0 * rz_sd,
            angular_speed=model.angular_speed,
        )
    raise TeachfitError(f"unknown search method {method!r}; choose from {METHODS}")


def task_follow_config(task: Task) -> FollowConfig:
    """The follower's settings for ``task``: the defaults, and where the task says so
    (``peg2d``) the lateral stiffnesses times ``stiffness_scale`` (the friction lag of the
    sliding part kept what it is at the default friction) and a hold once the part sank
    ``search_hold_depth``: pressed in with the across stiffness in every direction, not
    dragged on (it would wedge); where it has a ``search_tilt`` (sharp edges), tilted; the lag
    along the motion closed over :data:`TRACK_FEEL`."""
    hold = getattr(task, "search_hold_depth", None)
    scale = float(getattr(task, "stiffness_scale", 1.0))
    base = FollowConfig()
    across = scale * base.stiffness_across
    return FollowConfig(
        stiffness_along=scale * base.stiffness_along,
        stiffness_across=across,
        hold_depth=hold,
        hold_stiffness=None if hold is None else across,
        tilt=_tilt(task, scale * base.stiffness_along, base.push_force),
        track_feel=TRACK_FEEL,
    )


def _tilt(task: Task, stiffness: float, load: float) -> TiltConfig | None:
    """The tilted search where the task asks for one (``search_tilt`` > 0, rad; see
    :mod:`teachfit.skills.tilt`): the drop felt at half the upright hold depth (a tilted peg
    rests steadily on a flat top; its drop is ~ tan(tilt) x how far the rim is past the edge),
    the low rim slid up to a hole diameter after it; after a missed align it tries once at the
    task's ``jam_free_tilt`` where that is smaller, then at ``search_tilt`` again, and so on;
    a drop deeper than the tilted part can sink into the hole (:func:`tilted_drop` at the
    larger tilt, plus the hole's chamfer and ``OFF_MARGIN``) left the top over its outer
    edge: lifted back onto it; the set-points go a :func:`rim_lead` behind the trajectory, so
    that the low rim follows it."""
    angle = float(getattr(task, "search_tilt", 0.0))
    if angle <= 0.0:
        return _fit_tilt(task, stiffness, load)
    p = task.params
    jam_free = getattr(task, "jam_free_tilt", None)
    return TiltConfig(
        angle=angle,
        retry_angle=None if jam_free is None or jam_free >= angle else float(jam_free),
        drop_depth=0.5 * float(getattr(task, "search_hold_depth", 0.0)),
        lateral_reach=p.peg_diameter + p.clearance,
        stall_lag=wedge_lag(angle, p.friction, load, stiffness),
        off_depth=tilted_drop(angle, p.peg_diameter, p.clearance) + p.hole_chamfer + OFF_MARGIN,
        lead=rim_lead(angle, p.peg_diameter),
    )


#: factor on the slide's stall lead (:func:`~teachfit.skills.tilt.wedge_lag`) of the search alone
#: on a fit: on the FR3 the joints' friction holds the sliding part back as well, and at the bare
#: wedge lead the slide stopped 0.8-1.6 mm into a 2.5-4 mm way to the far wall, the align then
#: missed (round16-sharp-blind, fresh seed: 3 of 12 starts; at twice the lead, 0)
FIT_STALL_MARGIN = 2.0


def _fit_tilt(task: Task, stiffness: float, load: float) -> TiltConfig | None:
    """A task that knows its fit (:func:`~teachfit.skills.fit_context.fit_of`, the mesh
    tasks) with a sharp-edged part (tip chamfer below the clearance): the joined skill's tilted
    search (:func:`~teachfit.skills.fit_context.search_tilt_context`), so that the search
    alone and the joined skill's search node search alike. Upright, a sharp-edged part drops in
    only where its axis passes within the clearance of the hole's; the learned tours on the
    parts suite rarely pass there (round16-sharp-blind on fr3, 10 starts: 3/10; tilted 8/10)."""
    fit = fit_of(task)
    if fit is None or fit.tip_chamfer >= fit.clearance:
        return None
    ctx = search_tilt_context(fit)
    retry = ctx["search_retry_tilt"]
    lead, reach, corner = ctx["search_lead"], ctx["search_reach"], None
    if fit.corner > 0.0:  # corner first: the corner leads, the slide reaches the diagonal
        corner = math.atan2(fit.corner, fit.half_width)
        lead = rim_lead(ctx["search_tilt"], 2.0 * math.hypot(fit.half_width, fit.corner))
        reach = 2.0 * math.hypot(fit.hole_half_width, fit.corner + fit.clearance)
    return TiltConfig(
        angle=ctx["search_tilt"],
        retry_angle=retry if 0.0 < retry < ctx["search_tilt"] else None,
        drop_depth=ctx["search_drop"],
        lateral_reach=reach,
        stall_lag=FIT_STALL_MARGIN
        * wedge_lag(ctx["search_tilt"], ctx["search_friction"], load, stiffness),
        lead=lead,
        ramp_time=FIT_TILT_RAMP,
        corner=corner,
    )


def friction_floor(task: Task, config: FollowConfig) -> float:
    """The least feed-forward force (N) along the motion for ``task`` followed with
    ``config``: the sliding friction of the part pressed with the follower's push, where the
    task says what it is (``peg2d``'s :meth:`sliding_friction`), else 0."""
    friction = getattr(task, "sliding_friction", None)
    return 0.0 if friction is None else float(friction(config.push_force))


def run_search(
    robot: Robot,
    task: Task,
    model: SearchModel,
    start: Pose,
    traj: SearchTrajectory,
    *,
    feedforward: bool = True,
    config: FollowConfig | None = None,
) -> SearchRun:
    """Execute one search trajectory from ``start`` through the engine (``config``: the
    task's, :func:`task_follow_config`; the feed-forward at least :func:`friction_floor`)."""
    if config is None:
        config = task_follow_config(task)
    floor = friction_floor(task, config)
    setpoints = search_setpoints(
        traj, task, start, model if feedforward else None, friction_floor=floor
    )
    return SearchRun(run_trajectory(robot, task, setpoints, start, config), traj, setpoints)


def run_protocol(
    robot: Robot,
    task: Task,
    model: SearchModel,
    method: str,
    n_points: int,
    n_starts: int,
    protocol: str,
    seed: int,
    *,
    passes: int = 1,
    feedforward: bool = True,
    demo_start: Pose | None = None,
    config: FollowConfig | None = None,
    on_done: Callable[[SearchRun], None] | None = None,
) -> list[SearchRun]:
    """Ehlers et al.'s protocol: ``n_starts`` starts of the task's ``protocol`` (drawn with
    ``seed``; Table I's lie halfway between ``demo_start`` and the hole), a ``method`` search from
    each, TSHIX planned with :func:`~teachfit.execution.batch.episode_rng` ``(seed, i)`` (an ergodic
    trajectory is deterministic: planned once); ``on_done`` after each run."""
    if n_starts < 1:
        raise TeachfitError(f"number of starts must be >= 1, got {n_starts}")
    if passes > 1 and method != "tshix":
        raise TeachfitError(f"passes > 1 needs method tshix, not {method}")
    rng = np.random.default_rng(seed)
    starts = task.protocol.protocol_starts(protocol, n_starts, rng, demo_start)
    fixed = plan_search(model, method, n_points, rng) if method.startswith("ergodic") else None
    runs = []
    for i, start in enumerate(starts):
        traj = fixed or plan_search(model, method, n_points, episode_rng(seed, i), passes=passes)
        run = run_search(robot, task, model, start, traj, feedforward=feedforward, config=config)
        runs.append(run)
        if on_done is not None:
            on_done(run)
    return runs


def demo_start_pose(demo: str, task: str) -> Pose:
    """The start pose of the demonstration ``demo`` (``FILE.h5:INDEX``), which must show
    ``task`` (its name): it anchors Table I's starts."""
    from teachfit.demonstrations.dataset import read_demo

    d = read_demo(demo)
    if d.task != task:
        raise TeachfitError(f"--demo {demo} is a {d.task!r} demonstration, not {task!r}")
    return d.start_pose
