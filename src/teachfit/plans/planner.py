"""Motion planning of the moving part's 6-DOF pose guided by demonstrated key poses.

The loop of Wang et al. 2019 (docs/methods.md; the paper's Fig. 7): plan from the initial
to the final pose with RRT-Connect (OMPL, SE(3), validity by coal in Python: box or mesh checks, see
:mod:`.collision`); when an attempt finds no path within ``te`` seconds, insert the next ranked
key pose and plan segment by segment. A key pose in collision is first replaced by the nearest
collision-free pose sampled around it. The ranking puts first the chain of key poses joined by
free straight motions (:func:`~teachfit.plans.keyposes.straight_chain`; its motion checks are
reused by the attempts), then the rest by the paper's derivative. Where that chain needs more
than two key poses, the same greedy walk runs over the demonstration itself (about
:data:`CHAIN_NODES` of its poses, evenly in time) and, if it needs fewer, its poses
become candidates in place of evenly spaced ones (the count stays the task's): six evenly
spaced candidates can miss the poses that a short chain needs (L-groove seed 38: 4 key
poses through them, 2 through the demonstration). Each segment tries the
straight motion, then, between neighbouring key poses, the demonstrated motion, then
RRT-Connect; solved segments are reused by later attempts. The final path is shortcut and
smoothed (OMPL's PathSimplifier) and verified densely with our own interpolation.

Every query seeds OMPL's global RNG from its ``seed`` (:func:`seed_ompl`), so the samplers of
the planners and of the path simplifier it creates draw the same numbers whatever ran before in
the process (worker processes included). With a budget in collision checks
(``PlannerConfig.max_checks``) instead of seconds, a query's result is a function of its
inputs and seed alone, whatever the machine's speed or load.

Inside this module and :mod:`.ompl_space` (the OMPL boundary) states are ``(7,)`` arrays
``[x, y, z, qw, qx, qy, qz]``: ``L2G`` in m and a unit quaternion. Outside them, poses are
:class:`~teachfit.core.geometry.Pose`: :attr:`PlanResult.poses` and
:meth:`MotionPlanner.dense_poses`. Rotations go through the geometry kernel (scipy for batches,
its MuJoCo-backed matrix routine in the collision checks).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from typing import Protocol

import numpy as np
import ompl.base as ob
import ompl.geometric as og
from scipy.spatial.transform import Rotation

from teachfit.core.errors import PlanningError
from teachfit.core.geometry import (
    Pose,
    array_to_poses,
    poses_to_array,
    quat_angle,
    rotation_to_wxyz,
    wxyz_to_rotation,
)
from teachfit.plans.collision import CollisionChecker, pose_to_matrix
from teachfit.plans.keyposes import KeyPoses, rank_key_poses, straight_chain
from teachfit.plans.ompl_space import PLANNERS, matrix_to_state, seed_ompl, slerp
from teachfit.plans.plan_types import PlannerConfig, PlanResult
from teachfit.tasks.parts import Assembly


class DemoPoses(Protocol):
    """What the planner reads of a demonstration (a
    :class:`~teachfit.demonstrations.dataset.Demonstration`): the ``L2G`` positions (T, 3) in m
    and unit quaternions (T, 4) w-x-y-z; ``task`` and ``t`` are read where present."""

    @property
    def pos(self) -> np.ndarray: ...

    @property
    def quat(self) -> np.ndarray: ...


__all__ = [
    "PLANNERS",
    "MotionPlanner",
    "PlanResult",
    "PlannerConfig",
    "matrix_to_state",
    "seed_ompl",
]

#: demonstrated poses (about; evenly in time) the greedy straight chain looks at when the
#: candidates' own chain needs more than two (every 5th of the L-groove's 164), ~12 ms of
#: motion checks (CPU, busy machine) where it runs
CHAIN_NODES = 30


class MotionPlanner:
    """Plans ``L2G`` from ``asm.start`` to ``asm.goal``, optionally guided by a demonstration.

    Parameters
    ----------
    asm : Assembly
        The parts, start and goal poses, and sampling bounds.
    config : PlannerConfig
        Planner settings.

    Raises
    ------
    PlanningError
        Degenerate meshes, or start or goal pose in collision.
    """

    def __init__(self, asm: Assembly, config: PlannerConfig | None = None) -> None:
        self.asm = asm
        self.config = config or PlannerConfig()
        self.checker = CollisionChecker.of(asm)
        region = self.config.key_region
        self.key_region = asm.key_region if region is None else region
        self._near = CollisionChecker.of(asm, margin=self.key_region)
        self.start = matrix_to_state(asm.start)
        self.goal = matrix_to_state(asm.goal)
        for label, state in (("start", self.start), ("goal", self.goal)):
            if self._collides(state):
                depth = self.checker.distance(pose_to_matrix(state[:3], state[3:]))
                raise PlanningError(
                    f"{label} pose of {asm.task} is in collision (distance {depth:.2e} m)"
                )
        # radius of the moving part about its frame origin: converts rotations to motions
        self.radius = float(np.linalg.norm(asm.moving.vertices, axis=1).max())
        self.space = ob.SE3StateSpace()
        bounds = ob.RealVectorBounds(3)
        for i in range(3):
            bounds.setLow(i, float(asm.bounds[0, i]))
            bounds.setHigh(i, float(asm.bounds[1, i]))
        self.space.setBounds(bounds)
        # weight rotations by the part's radius, so the SE(3) metric approximates how far the
        # part's farthest point moves (a plain sum of metres and radians would not)
        self.space.setSubspaceWeight(1, self.radius)
        self.si = ob.SpaceInformation(self.space)
        checker = self.checker

        def valid(s: ob.State) -> bool:
            r = s.rotation()
            return not checker.collides_xyzq(s.getX(), s.getY(), s.getZ(), r.w, r.x, r.y, r.z)

        self._valid = valid  # OMPL keeps a reference; keep ours alive as long as the planner
        self.si.setStateValidityChecker(valid)
        self.si.setStateValidityCheckingResolution(
            self.config.resolution / self.space.getMaximumExtent()
        )
        self.si.setup()
        self.approach = self._approach(getattr(asm, "approach", None))

    def _approach(self, T: np.ndarray | None) -> np.ndarray | None:
        """The assembly's pre-insertion pose (a mesh task's: aligned just above the entry),
        checked free and joined to the goal by a free straight motion; None without one."""
        if T is None:
            return None
        state = matrix_to_state(T)
        if self._collides(state) or not self.si.checkMotion(
            self._to_ompl(state), self._to_ompl(self.goal)
        ):
            raise PlanningError(
                f"{self.asm.task}: the straight insertion from the approach pose to the goal "
                "collides; check the task's insertion axis and hole frame"
            )
        return state

    # -- states -------------------------------------------------------------------------------
    def _collides(self, s: np.ndarray) -> bool:
        return self.checker.collides_xyzq(*np.asarray(s, dtype=float).tolist())

    def _to_ompl(self, s: np.ndarray) -> ob.State:
        state = self.space.allocState()
        state.setXYZ(float(s[0]), float(s[1]), float(s[2]))
        r = state.rotation()
        q = s[3:] / np.linalg.norm(s[3:])
        r.w, r.x, r.y, r.z = (float(v) for v in q)
        return state

    @staticmethod
    def _from_ompl(state: ob.State) -> np.ndarray:
        r = state.rotation()
        return np.array([state.getX(), state.getY(), state.getZ(), r.w, r.x, r.y, r.z])

    def _distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Motion bound (m) between state a (7,) and states b (N, 7)."""
        angle = quat_angle(a[3:], b[:, 3:])
        return np.linalg.norm(b[:, :3] - a[:3], axis=1) + self.radius * angle

    # -- key poses ----------------------------------------------------------------------------
    def repair(self, state: np.ndarray, rng: np.random.Generator) -> np.ndarray | None:
        """Nearest collision-free pose sampled around ``state`` (itself when free).

        Samples Gaussian perturbations at growing radii (0.5 mm and 0.5 deg, doubling) and
        returns the valid sample nearest to ``state``; None when none is found up to 16 mm.
        """
        if not self._collides(state):
            return state
        lo, hi = self.asm.bounds
        for level in range(6):
            sigma_p, sigma_r = 0.0005 * 2**level, np.radians(0.5) * 2**level
            n = self.config.repair_samples
            dp = rng.normal(0.0, sigma_p, (n, 3))
            dr = Rotation.from_rotvec(rng.normal(0.0, sigma_r, (n, 3)))
            q = rotation_to_wxyz(dr * wxyz_to_rotation(state[3:]), canonical=False)
            cand = np.concatenate([state[:3] + dp, q], axis=1)
            inside = np.all((cand[:, :3] >= lo) & (cand[:, :3] <= hi), axis=1)
            cand = cand[inside]
            free = np.array([not self._collides(c) for c in cand], dtype=bool)
            if free.any():
                ok = cand[free]
                return ok[int(np.argmin(self._distance(state, ok)))]
        return None

    def _repair_all(self, keys: KeyPoses, rng: np.random.Generator) -> dict[int, np.ndarray | None]:
        """:meth:`repair` of every candidate, by its position in ``keys``."""
        states = matrix_to_state(keys.L2G)
        return {i: self.repair(s, rng) for i, s in enumerate(states)}

    # -- segments -----------------------------------------------------------------------------
    def _plan_segment(
        self,
        a: np.ndarray,
        b: np.ndarray,
        budget: float,
        by_checks: bool,
        via: np.ndarray | None = None,
        try_straight: bool = True,
    ) -> np.ndarray | None:
        """Path from ``a`` to ``b`` within ``budget`` (collision checks or seconds), or None.

        Tries the straight motion (unless ``try_straight`` is False: known to collide), then
        the demonstrated motion ``via`` ((M, 7) states between the two key poses, when given)
        if each of its steps is free, then RRT-Connect.
        """
        sa, sb = self._to_ompl(a), self._to_ompl(b)
        if try_straight and self.si.checkMotion(sa, sb):
            return np.stack([a, b])
        if via is not None and len(via) > 0:
            demo_path = np.concatenate([a[None], via, b[None]])
            states = [self._to_ompl(q) for q in demo_path]
            if all(self.si.checkMotion(p, q) for p, q in zip(states[:-1], states[1:], strict=True)):
                return demo_path
        if budget < (1.0 if by_checks else 1e-3):
            return None
        ss = og.SimpleSetup(self.si)
        # ompl 2.0.1 crashes if SimpleSetup.setup() runs before start and goal are set; solve()
        # calls setup() itself, so set them first and never call setup() explicitly.
        ss.setStartAndGoalStates(sa, sb)
        ss.setPlanner(PLANNERS[self.config.planner](self.si))
        if by_checks:
            checker, limit = self.checker, self.checker.n_checks + int(budget)
            ss.solve(ob.PlannerTerminationCondition(lambda: checker.n_checks >= limit))
        else:
            ss.solve(float(budget))
        if not ss.haveExactSolutionPath():
            return None
        path = ss.getSolutionPath()
        return np.array([self._from_ompl(path.getState(i)) for i in range(path.getStateCount())])

    # -- public -------------------------------------------------------------------------------
    def plan(
        self, demo: DemoPoses | None = None, *, te: float | None = None,
        max_checks: int | None = None, seed: int = 0,
    ) -> PlanResult:  # fmt: skip
        """Plan from start to goal, inserting ranked key poses of ``demo`` as needed.

        Parameters
        ----------
        demo : Demonstration or None
            Demonstration of ``L2G`` for this task (``frame="G"``, ``child_frame="L"``); None
            plans without one (a single attempt of ``te`` seconds).
        te : float, optional
            Budget (s) per attempt; defaults to ``config.te`` (see :class:`PlannerConfig`).
        max_checks : int, optional
            Budget per attempt in collision checks instead of seconds; defaults to
            ``config.max_checks`` (None: the budget is ``te``).
        seed : int
            Seed of the key-pose repair sampling and of OMPL's samplers (:func:`seed_ompl`).

        Raises :class:`PlanningError` for a demonstration of another task or with fewer than
        two poses, and for a bad budget or seed.
        """
        t0 = time.perf_counter()
        checks0 = self.checker.n_checks
        by_checks, per_attempt, budget_label = self._budget(te, max_checks)
        seed_ompl(seed)
        rng = np.random.default_rng(seed)
        keys, repaired, straight = self._candidates(demo, rng)
        n_cand = 0 if keys is None else len(keys.indices)
        run = _Attempts(self, by_checks, per_attempt, straight, self._demonstrated(demo, keys))
        path, chosen = None, list(range(n_cand))
        for k in range(min(self.config.first_key_poses, n_cand), n_cand + 1):
            chosen = [] if keys is None else sorted(int(i) for i in keys.order[:k])
            path = run.attempt(*self._waypoints(chosen, repaired, n_cand))
            if path is not None:
                break
        t_plan = time.perf_counter() - t0
        if path is None:  # every attempt failed
            replaced = sum(1 for v in repaired.values() if v is None)
            message = f"no path within {budget_label} per attempt after {run.count} attempt(s)"
        else:
            path = self._finish(path)
            replaced = self._replaced(keys, repaired, chosen)
            message = "ok" if path is not None else "path failed dense verification"
        return PlanResult(
            success=path is not None,
            path=np.empty((0, 7)) if path is None else path,
            time_s=t_plan,
            total_s=time.perf_counter() - t0,
            attempts=run.count,
            used_key_poses=len(chosen),
            candidates=n_cand,
            replaced_key_poses=replaced,
            collision_checks=self.checker.n_checks - checks0,
            planner=self.config.planner,
            message=message,
            key_poses=keys,
        )

    def _waypoints(
        self, chosen: list[int], repaired: dict[int, np.ndarray | None], n_cand: int
    ) -> tuple[list[int], dict[int, np.ndarray]]:
        """An attempt's waypoint ids and states: the start (-1), the ``chosen`` key poses that
        have a repair, the approach above the goal where the task has one (``n_cand + 1``),
        and the goal (``n_cand``)."""
        ids = [-1] + [i for i in chosen if repaired[i] is not None] + [n_cand]
        states = {-1: self.start, n_cand: self.goal}
        states |= {i: s for i in ids[1:-1] if (s := repaired[i]) is not None}
        if self.approach is not None:  # the goal is reached by the straight insertion
            ids.insert(-1, n_cand + 1)
            states[n_cand + 1] = self.approach
        return ids, states

    def _budget(self, te: float | None, max_checks: int | None) -> tuple[bool, float, str]:
        """``(by_checks, budget per attempt, its label)``: collision checks when ``max_checks``
        (or the config's) is set, else seconds (``te``, the config's, or a default by the
        checker's kind)."""
        if te is None:
            te = self.config.te or (0.002 if self.checker.on_boxes else 0.02)
        te = float(te)
        if not te > 0:
            raise PlanningError(f"te must be > 0 s, got {te!r}")
        checks = self.config.max_checks if max_checks is None else max_checks
        if checks is not None and checks < 1:
            raise PlanningError(f"max_checks must be >= 1, got {checks!r}")
        if checks is not None:
            return True, float(checks), f"{checks} collision checks"
        return False, te, f"te={te} s"

    def _candidates(
        self, demo: DemoPoses | None, rng: np.random.Generator
    ) -> tuple[KeyPoses | None, dict[int, np.ndarray | None], dict[tuple[int, int], bool]]:
        """The demonstration's ranked key poses (None without one), their repairs by position,
        and the straight motions between them found free or not while ranking."""
        if demo is None:
            return None, {}, {}
        keys, eligible = self._rank(demo)
        repaired = self._repair_all(keys, rng)
        keys, straight, n_chain = self._chain_first(keys, repaired)
        shorter = self._demo_chain(demo, n_chain) if n_chain > 2 else None
        if shorter is not None:
            keys, _ = self._rank(demo, include=shorter, eligible=eligible)
            repaired = self._repair_all(keys, rng)
            keys, straight = self._chain_through(keys, shorter)
        return keys, repaired, straight

    @staticmethod
    def _replaced(
        keys: KeyPoses | None, repaired: dict[int, np.ndarray | None], chosen: list[int]
    ) -> int:
        """How many of the ``chosen`` key poses were in collision (replaced or dropped)."""
        if keys is None or not chosen:
            return 0
        demo_states = matrix_to_state(keys.L2G)
        return sum(
            1 for i in chosen if (r := repaired[i]) is None or not np.array_equal(r, demo_states[i])
        )

    def _rank(
        self,
        demo: DemoPoses,
        include: np.ndarray | None = None,
        eligible: np.ndarray | None = None,
    ) -> tuple[KeyPoses, np.ndarray | None]:
        """The demonstration's ranked candidates (``include``: samples that are candidates in
        any case) and the mask of samples near contact they were taken from (``eligible``:
        that mask from an earlier call, not computed again)."""
        task = getattr(demo, "task", None)
        if task != self.asm.task:
            raise PlanningError(
                f"demonstration is for task {task!r}, but the parts are {self.asm.task!r}"
            )
        t = np.asarray(getattr(demo, "t", []), dtype=float)
        if t.ndim != 1 or len(t) < 2:
            raise PlanningError(f"demonstration has {t.size} pose(s); need at least 2")
        pos = np.asarray(demo.pos, dtype=float)
        quat = np.asarray(demo.quat, dtype=float)
        shapes_ok = pos.shape == (len(t), 3) and quat.shape == (len(t), 4)
        if eligible is None and self.key_region > 0 and shapes_ok:
            # every third sample, each standing for its neighbours (a 30 Hz demonstration moves
            # ~1 mm a sample): the region is a coarse mask, and this is a third of the checks
            step = 3
            near = [self._near.collides_xyzq(*pos[i], *quat[i]) for i in range(0, len(t), step)]
            eligible = np.repeat(np.array(near, dtype=bool), step)[: len(t)]
        keys = rank_key_poses(
            t,
            pos,
            quat,
            self.asm.n_candidates,
            param=self.asm.key_param,
            char_length=self.radius,
            eligible=eligible,
            include=include,
        )
        return keys, eligible

    def _demonstrated(
        self, demo: DemoPoses | None, keys: KeyPoses | None
    ) -> Callable[[int, int], np.ndarray | None]:
        """``via(a, b)``: the demonstrated states strictly between neighbouring nodes ``a`` and
        ``b = a + 1`` (-1 the start, ``0 .. K-1`` the candidates, ``K`` the goal); None for
        other pairs (the key poses between them are what the planner inserts), for the
        approach of a mesh task, or without a demonstration."""
        if demo is None or keys is None:
            return lambda a, b: None
        demo_states = _demo_states(demo)
        n, last = len(keys.indices), len(demo_states) - 1

        def via(a: int, b: int) -> np.ndarray | None:
            if b > n or b != a + 1:
                return None
            ia = 0 if a < 0 else int(keys.indices[a])
            ib = last if b == n else int(keys.indices[b])
            return demo_states[ia + 1 : ib]

        return via

    def _demo_chain(self, demo: DemoPoses, than: int) -> np.ndarray | None:
        """Sample indices of the demonstration's own greedy straight chain
        (:func:`straight_chain` over :data:`CHAIN_NODES` of its poses, from the start to the goal
        or approach pose) if it needs fewer than ``than`` poses, at most the task's candidate
        count, every link a free straight motion (the walk steps on to the next pose where
        none connects); else None."""
        states = _demo_states(demo)
        step = max(1, len(states) // CHAIN_NODES)
        idx = np.arange(step, len(states) - 1, step)
        end = self.goal if self.approach is None else self.approach
        nodes = {-1: self.start, len(idx): end} | {i: states[j] for i, j in enumerate(idx)}
        free: dict[int, bool] = {}
        linked: set[tuple[int, int]] = set()

        def ok(i: int) -> bool:
            if i not in free:
                free[i] = not self._collides(nodes[i])
            return free[i]

        def connects(a: int, b: int) -> bool:
            if (
                ok(a)
                and ok(b)
                and self.si.checkMotion(self._to_ompl(nodes[a]), self._to_ompl(nodes[b]))
            ):
                linked.add((a, b))
                return True
            return False

        chain = straight_chain(len(idx), connects)
        hops = [-1, *chain, len(idx)]
        if len(chain) >= than or len(chain) > self.asm.n_candidates:
            return None
        if any(hop not in linked for hop in zip(hops[:-1], hops[1:], strict=True)):
            return None
        return idx[chain]

    def _chain_through(
        self, keys: KeyPoses, samples: np.ndarray
    ) -> tuple[KeyPoses, dict[tuple[int, int], bool]]:
        """``keys`` reordered with the candidates at the demonstration's ``samples`` first (a
        chain :meth:`_demo_chain` found joined by free straight motions, collision-free, so
        not repaired), then the rest by the derivative rule; and those motions, by pair of
        the attempts' node ids, as :meth:`_chain_first` gives them."""
        n = len(keys.indices)
        end = n if self.approach is None else n + 1
        chain = [int(np.searchsorted(keys.indices, j)) for j in samples]
        nodes = [-1, *chain, end]
        straight = {(a, b): True for a, b in zip(nodes[:-1], nodes[1:], strict=True)}
        return _chain_ahead(keys, chain), straight

    def _chain_first(
        self, keys: KeyPoses, repaired: dict[int, np.ndarray | None]
    ) -> tuple[KeyPoses, dict[tuple[int, int], bool], int]:
        """``keys`` reordered: the straight chain (:func:`straight_chain`) first, then the rest
        by the derivative rule; the straight motions tested meanwhile (OMPL's motion check,
        the attempts' own), by pair of the attempts' node ids, for the attempts to reuse; and
        the chain's length."""
        n = len(keys.indices)
        end = n if self.approach is None else n + 1  # the attempts' id of the chain's last node
        nodes: dict[int, np.ndarray | None] = {
            -1: self.start,
            n: self.goal if self.approach is None else self.approach,
        }
        nodes |= repaired
        straight: dict[tuple[int, int], bool] = {}

        def connects(a: int, b: int) -> bool:
            sa, sb = nodes[a], nodes[b]
            ok = (
                sa is not None
                and sb is not None
                and bool(self.si.checkMotion(self._to_ompl(sa), self._to_ompl(sb)))
            )
            straight[(a, end if b == n else b)] = ok
            return ok

        chain = straight_chain(n, connects)
        return _chain_ahead(keys, chain), straight, len(chain)

    def _finish(self, path: np.ndarray) -> np.ndarray | None:
        """Shortcut and smooth ``path`` with OMPL, then verify densely; None if unverifiable."""
        cfg = self.config
        if (cfg.shortcut or cfg.smooth_steps > 0) and len(path) > 2:
            geo = og.PathGeometric(self.si, [self._to_ompl(s) for s in path])
            simplifier = og.PathSimplifier(self.si)
            if cfg.shortcut:
                simplifier.reduceVertices(geo)
            if cfg.smooth_steps > 0:
                simplifier.smoothBSpline(geo, cfg.smooth_steps)
            smooth = np.array(
                [self._from_ompl(geo.getState(i)) for i in range(geo.getStateCount())]
            )
            if self.verify(smooth):
                return smooth
        return path if self.verify(path) else None

    def densify(self, path: np.ndarray, resolution: float | None = None) -> np.ndarray:
        """Interpolate ``path`` (N, 7) so no part point moves more than ``resolution`` (m) a step.

        Positions are interpolated linearly and orientations by slerp (as OMPL's SE(3) does).
        """
        res = self.config.verify_resolution if resolution is None else resolution
        out = [path[:1]]
        for a, b in zip(path[:-1], path[1:], strict=True):
            n = max(int(np.ceil(self._distance(a, b[None])[0] / res)), 1)
            s = np.linspace(0.0, 1.0, n + 1)[1:]
            q = slerp(a[3:], b[3:], s)
            out.append(np.concatenate([a[:3] + s[:, None] * (b[:3] - a[:3]), q], axis=1))
        return np.concatenate(out)

    def dense_poses(
        self, poses: Sequence[Pose], resolution: float | None = None
    ) -> tuple[Pose, ...]:
        """:meth:`densify` for poses ``L2G`` (e.g. :attr:`PlanResult.poses`): the same
        interpolation, so no part point moves more than ``resolution`` (m) a step."""
        if len(poses) == 0:
            return ()
        return array_to_poses(self.densify(poses_to_array(poses), resolution))

    def verify(self, path: np.ndarray) -> bool:
        """True when every state of the densified ``path`` is collision-free and inside bounds."""
        dense = self.densify(path)
        lo, hi = self.asm.bounds
        if np.any(dense[:, :3] < lo - 1e-9) or np.any(dense[:, :3] > hi + 1e-9):
            return False
        return not any(self._collides(s) for s in dense)


def _demo_states(demo: DemoPoses) -> np.ndarray:
    """(T, 7) states ``[x, y, z, qw, qx, qy, qz]`` of a demonstration's ``L2G``."""
    pos = np.asarray(demo.pos, dtype=float)
    return np.concatenate([pos, np.asarray(demo.quat, dtype=float)], axis=1)


def _chain_ahead(keys: KeyPoses, chain: list[int]) -> KeyPoses:
    """``keys`` with the candidates ``chain`` (positions, in order) ranked first, then the rest
    in their order."""
    rest = [int(i) for i in keys.order if int(i) not in chain]
    return dataclasses.replace(keys, order=np.array(chain + rest, dtype=int))


class _Attempts:
    """The planner's attempts of one query: each plans the segments between its key poses,
    reusing the segments solved before and giving up on one that failed before with as much
    budget (another key pose is then inserted)."""

    def __init__(
        self,
        planner: MotionPlanner,
        by_checks: bool,
        per_attempt: float,
        straight: dict[tuple[int, int], bool],
        via: Callable[[int, int], np.ndarray | None],
    ) -> None:
        self.planner, self.by_checks, self.per_attempt = planner, by_checks, per_attempt
        self.straight, self.via = straight, via
        self.solved: dict[tuple[int, int], np.ndarray] = {}
        self.failed: dict[tuple[int, int], float] = {}
        self.count = 0

    def attempt(self, ids: list[int], states: dict[int, np.ndarray]) -> np.ndarray | None:
        """The path through ``states[ids]`` in order, or None when a segment fails."""
        pl, checker = self.planner, self.planner.checker
        self.count += 1
        ta, ca = time.perf_counter(), checker.n_checks
        pieces = []
        for a, b in zip(ids[:-1], ids[1:], strict=True):
            if (a, b) in self.solved:
                pieces.append(self.solved[(a, b)])
                continue
            spent = checker.n_checks - ca if self.by_checks else time.perf_counter() - ta
            budget = self.per_attempt - spent
            if self.failed.get((a, b), -1.0) * 1.5 >= budget:
                return None  # failed before with as much budget: insert another key pose
            seg: np.ndarray | None
            if self.straight.get((a, b)):  # found free while ranking
                seg = np.stack([states[a], states[b]])
            else:
                try_straight = (a, b) not in self.straight
                seg = pl._plan_segment(
                    states[a], states[b], budget, self.by_checks, self.via(a, b), try_straight
                )
            if seg is None:
                self.failed[(a, b)] = budget
                return None
            self.solved[(a, b)] = seg
            pieces.append(seg)
        return np.concatenate([pieces[0]] + [p[1:] for p in pieces[1:]])
