"""Learned search (Ehlers et al. 2019) as a manipulation primitive: the recovery of a skill graph.

:class:`LearnedSearch` is Ehlers et al.'s exception strategy inside Johannsmeier et al.'s skill
formalism. When the node is entered it plans a TSHIX tour through ``n_points`` samples of the
learned exploration distribution, starting *where the skill is* (the measured TCP pose, task frame),
and then follows it with the compliant set-point follower of :mod:`teachfit.skills.follow` (stiff
along the motion, soft across it, pressed onto the surface) plus the GMR feed-forward wrench the
model gives for each planned step (Ehlers et al. 2019, Sec. III-C).

Where the distribution is put. A search model is learned in the search frame of each
demonstration (origin at the teacher's start, world axes); its mean records how far the
teacher happened to start from the hole (a worst-case offset, centimetres), not where the hole
is relative to a skill that failed to align. What transfers is the *shape* of the human search
(the covariances: how wide and along which directions, and the rz spread) and the dynamics
(the feed-forward). So the mixture is re-centred on the skill's belief -- the estimated hole
(task-frame origin, estimated yaw) -- keeping each component's offset from the mixture mean,
and its covariances are scaled by ``scale²``: the learned ``search_scale`` matches the human's
spread to the size of the taught-hole error. That spread is the human's own, set by how far
the teacher started from the hole (e.g. 4 mm: an RMS radius of about 2 mm); where the taught
hole may be off by more, ``radius`` (the skill's ``search_radius``, m) scales the spread up to
at least that RMS radius in the surface plane -- else the tour never reaches the hole. The
tour itself starts at the current pose.

Along the task z the set-point follows the measured TCP, so only ``push`` presses the part
onto the surface and it can drop freely into the hole: a set-point held at a fixed height would
be tracked by an adaptive controller, whose learned feed-forward then cancels the push and
lifts the part off the surface within seconds.

Timing follows the teacher's speeds scaled by ``speed``. The orientation is blended from the
entry orientation (e.g. a tilted part after a lateral move) to the planned one over the first
``BLEND`` seconds so the set-point does not jump.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from scipy.spatial.transform import Rotation

from teachfit.core.errors import ModelError, PlanningError, SkillError
from teachfit.core.geometry import rotation_to_wxyz, wxyz_to_rotation, yaw_of
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.models.exploration import ExplorationDistribution
from teachfit.models.search_model import SearchModel
from teachfit.skills.follow import FollowConfig, _FollowRun
from teachfit.skills.follower import TRACK_FEEL
from teachfit.skills.params import Value, resolve
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.primitive import Primitive, PrimitiveRun
from teachfit.trajectories.tshix import TshixPlanner

#: s over which the orientation set-point turns from the entry orientation to the planned one
BLEND = 0.3
#: search DOF -> index of the wrench component its feed-forward acts on (task frame)
WRENCH_INDEX = {"x": 0, "y": 1, "z": 2, "rz": 5}


def surface_radius(ex: ExplorationDistribution) -> float:
    """The RMS radius (m) of ``ex`` in the surface plane: ``sqrt(var x + var y)`` of the
    mixture over its ``x`` and ``y`` DOFs (0 without either)."""
    idx = [j for j, d in enumerate(ex.dims) if d in ("x", "y")]
    return float(np.sqrt(np.trace(ex.cov[np.ix_(idx, idx)]))) if idx else 0.0


def recentred(
    ex: ExplorationDistribution, scale: float, radius: float = 0.0
) -> ExplorationDistribution:
    """``ex`` moved so that its mixture mean is 0, covariances times ``scale²``; component
    offsets from the mixture mean scale by ``scale`` too (the shape is kept). ``radius`` (m,
    0: none) is the least :func:`surface_radius` of the result: a smaller scaled spread is
    scaled up to it (a human spread narrower than the taught hole's error)."""
    if not (math.isfinite(scale) and scale > 0):
        raise SkillError(f"search scale must be > 0, got {scale}")
    if not (math.isfinite(radius) and radius >= 0):
        raise SkillError(f"search radius must be >= 0 m, got {radius}")
    spread = surface_radius(ex)
    if spread > 0:
        scale = max(scale, radius / spread)
    means = (ex.means - ex.mean) * scale
    return ExplorationDistribution(ex.dims, ex.weights, means, ex.covs * scale**2)


def states_to_setpoints(
    t: np.ndarray,
    states: np.ndarray,
    dims: tuple[str, ...],
    z: float,
    model: SearchModel | None,
    entry_quat: np.ndarray | None = None,
    name: str = "tshix",
) -> SetpointTrajectory:
    """Task-frame set-points for search states ``(T, D)`` at times ``t`` (s): positions
    ``(x, y, z)`` (m; missing DOFs 0), upright yaw ``rz`` (0 without it), the model's GMR
    feed-forward on the searched wrench components, the orientation blended from
    ``entry_quat`` over :data:`BLEND` s."""
    n = states.shape[0]
    pos = np.zeros((n, 3))
    pos[:, 2] = z
    for j, d in enumerate(dims):
        if d in ("x", "y", "z"):
            pos[:, "xyz".index(d)] = states[:, j]
    rz = states[:, dims.index("rz")] if "rz" in dims else np.zeros(n)
    planned = Rotation.from_euler("z", rz[:, None])
    if entry_quat is not None:
        alpha = np.clip(t / BLEND, 0.0, 1.0)[:, None]
        delta = (wxyz_to_rotation(entry_quat).inv() * planned).as_rotvec()
        planned = wxyz_to_rotation(entry_quat) * Rotation.from_rotvec(alpha * delta)
    ff = np.zeros((n, 6))
    if model is not None and model.dynamics is not None:
        actions = model.feedforward_along(t, states)
        for j, d in enumerate(dims):
            ff[:, WRENCH_INDEX[d]] = actions[:, j]
    return SetpointTrajectory(t, pos, rotation_to_wxyz(planned), ff, name=name)


def plan_tour(
    model: SearchModel,
    planner: TshixPlanner,
    n: int,
    rng: np.random.Generator,
    pc: Percept,
    blend: bool = True,
    shift: tuple[float, float] = (0.0, 0.0),
) -> SetpointTrajectory:
    """A TSHIX tour of ``n`` points from the measured pose in ``pc`` (moved by ``shift``, m,
    x-y) as task-frame set-points at the set-point's height (:func:`states_to_setpoints`;
    ``blend``: the orientation from the measured one, else the planned one from the start)."""
    x, y = pc.p[0] + shift[0], pc.p[1] + shift[1]
    here = {"x": x, "y": y, "z": pc.p[2], "rz": yaw_of(pc.q)}
    start = np.array([here[d] for d in model.dims])
    try:
        traj = planner.plan(n, rng, start)
    except (PlanningError, ModelError) as exc:
        raise SkillError(f"search planning failed: {exc}") from exc
    entry = pc.q.copy() if blend else None
    return states_to_setpoints(traj.t, traj.states, model.dims, float(pc.p_d[2]), model, entry)


@dataclass(frozen=True)
class Tour:
    """How a learned search tours (:meth:`LearnedSearch.tour`): ``n`` points per tour,
    the ``planner``, the follow config ``cfg``, the sampler ``rng``, ``repeat``: a tour
    without a catch is followed by another from where it ended."""

    n: int
    planner: TshixPlanner
    cfg: FollowConfig
    rng: np.random.Generator
    repeat: bool


@dataclass(frozen=True)
class LearnedSearch(Primitive):
    """Search with a learned model from where the skill is; see the module docstring.

    ``n_points`` TSHIX samples (rounded), ``scale`` of the exploration spread (``radius``:
    its least RMS radius in the surface plane, m; see :func:`recentred`), ``speed``
    factor on the teacher's speeds, ``push`` (N) onto the surface, ``seed`` of the sampler
    (each entry of the node draws fresh samples from it), ``repeat`` (> 0: a finished tour
    without a catch plans the next from where it ended, so the search ends only by the node's
    time limit; 0: one tour, done when it ends, as Ehlers et al.'s). ``follow`` sets the compliance
    (its ``push_force`` is replaced by ``push``). Built in code only (it holds a model).
    """

    model: SearchModel
    n_points: Value = "search_points"
    scale: Value = "search_scale"
    speed: Value = "search_speed"
    push: Value = "search_push"
    seed: Value = "search_seed"
    radius: Value = "search_radius"
    repeat: Value = "search_repeat"
    follow: FollowConfig = FollowConfig(settle_time=0.0, track_feel=TRACK_FEEL)
    kind: ClassVar[str] = "learned_search"

    def compile(self, values: Mapping[str, float]) -> PrimitiveRun:
        if self.follow.tilt is not None:
            raise SkillError(
                "learned_search follows upright: a tilted search is a graph of its own"
            )
        tour = self.tour(values)
        return _SearchRun(self.model, tour.planner, tour.n, tour.cfg, tour.rng, tour.repeat)

    def tour(self, values: Mapping[str, float]) -> Tour:
        """The tours' settings with ``values``: points, planner, follow config (the push
        set), the sampler and whether a tour without a catch is followed by another."""
        n = int(round(resolve(self.n_points, values)))
        if n < 2:
            raise SkillError(f"search needs at least 2 points, got {n}")
        speed = resolve(self.speed, values)
        push = resolve(self.push, values)
        if not (math.isfinite(speed) and speed > 0 and math.isfinite(push) and push >= 0):
            raise SkillError(f"search speed must be > 0 and push >= 0, got {speed}, {push}")
        ex = recentred(
            self.model.exploration, resolve(self.scale, values), resolve(self.radius, values)
        )
        ang = None if self.model.angular_speed is None else self.model.angular_speed * speed
        planner = TshixPlanner(ex, self.model.speed * speed, ang)
        cfg = FollowConfig(**{**self.follow.__dict__, "push_force": push, "anchor": "frame"})
        rng = np.random.default_rng(int(resolve(self.seed, values)))
        return Tour(n, planner, cfg, rng, resolve(self.repeat, values) > 0)

    def describe(self) -> str:
        return (
            f"TSHIX search from here ({self.n_points} points of the {self.model.task} model "
            f"x {self.scale}, push {self.push} N)"
        )

    def to_toml(self) -> dict[str, Any]:
        raise SkillError("a learned_search node holds a search model and has no TOML form")


class _SearchRun(PrimitiveRun):
    def __init__(
        self,
        model: SearchModel,
        planner: TshixPlanner,
        n: int,
        cfg: FollowConfig,
        rng: np.random.Generator,
        repeat: bool = False,
    ) -> None:
        self.model, self.planner, self.n, self.cfg, self.rng = model, planner, n, cfg, rng
        self.repeat = repeat
        self.t0 = 0.0
        self.dims = model.dims
        self.follow: _FollowRun | None = None
        self.trajectory: SetpointTrajectory | None = None

    def enter(self, pc: Percept) -> None:
        self.t0 = 0.0
        self._plan(pc)

    def _plan(self, pc: Percept) -> None:
        """A tour from the measured pose, followed from node time ``t0`` on."""
        self.trajectory = plan_tour(self.model, self.planner, self.n, self.rng, pc)
        self.follow = _FollowRun(self.trajectory, self.cfg)
        self.follow.enter(pc)

    def command(self, pc: Percept, out: MPCommand) -> None:
        assert self.follow is not None, "enter() first"
        t_node = pc.t_node
        pc.t_node = t_node - self.t0  # the tour's own clock
        try:
            self.follow.command(pc, out)
        finally:
            pc.t_node = t_node
        pc.p_d[2] = pc.p[2]  # force control along z: only the push presses (see the docstring)
        out.twist[2] = 0.0
        if pc.done and self.repeat:  # a tour without a catch: another one from here
            self.t0 = t_node
            self._plan(pc)
