"""How a set-point trajectory is followed: :class:`FollowConfig`, and :class:`Follower`, the
per-execution state of one follower shared by the nodes that follow one trajectory (the
upright follower of :mod:`teachfit.skills.follow`, the phases of a tilted search in
:mod:`teachfit.skills.tilt_phases`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teachfit.control.impedance import aligned_stiffness
from teachfit.core.errors import SkillError
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.tilt import TiltConfig

#: s, the searches' loop on their lag along the motion (:class:`FollowConfig` ``track_feel``).
#: Without it the FR3's part trailed its set-point by 0.5-1.5 mm (median per start; the arm's
#: joint friction, which the demonstration's feed-forward does not cover everywhere) and the
#: tour passed the hole 1.1-1.5 mm off where it was planned within 0.2 mm: arm Table I
#: (30 starts, the same run) TSHIX 24 -> 27/30, TSHIX-iid 25 -> 28/30, ergodic 18 -> 24/30 with
#: 0.1 s (0.3 s: 27, 28, 23); on the floating tool 30, 28, 26 -> 30, 27, 27. The joined
#: skill's search on the FR3 (parts suite, 20 trials at 3 mm): rect16x10-chamfer-blind 16 -> 18,
#: round12-chamfer-blind 18 -> 19; socket3d at 3-5 mm 28 -> 30 of 30
TRACK_FEEL = 0.1


@dataclass(frozen=True)
class FollowConfig:
    """How a set-point trajectory is followed (N/m, N·m/rad, N, s).

    ``stiffness_along`` / ``stiffness_across`` act in the x-y plane along / across the
    direction of the set-point's motion (``aligned=False``: ``stiffness_along`` everywhere);
    ``push_force`` presses the part onto the surface; ``settle_time`` is how long to wait after
    the trajectory ends; ``max_force`` (N) ends the execution (force limit); ``anchor``:
    ``"frame"`` follows the trajectory as given in the task frame, ``"entry"`` translates it
    so that it starts where the set-point is when the node is entered. ``press_feel`` (s), when
    positive, closes a slow loop on the press as a person pressing by feel does: while in
    contact (measured f_z above half the wanted), the push is corrected by the integral of the
    wanted minus the measured f_z over ``press_feel`` (clipped to half ``push_force``); 0 (the
    default) pushes open loop. ``hold_depth`` (m, None: off): once the TCP has sunk that far
    below its height on entering the node (the part dropped into the hole), the x-y set-point
    stays where the part is and only the push goes on, as a person who feels the part drop
    stops moving it sideways (dragged on, a part caught in a hole with high friction wedges
    instead of sliding in). ``hold_stiffness`` (N/m, None: unchanged): the lateral stiffness,
    the same in every x-y direction, once held, so that the chamfers can centre the pressed
    part (a hand that felt the drop also relaxes sideways). ``tilt`` (None: upright): search
    with the part tilted, and on the drop slide it to the hole's wall and align it upright
    (:mod:`teachfit.skills.tilt`: a skill graph of its own; its align node is a hold, with
    ``hold_stiffness``). ``track_feel`` (s), when positive and searching, closes a slow loop on
    the lag along the motion, as a person who feels the part drag pushes harder: while the
    part is pressed on a surface, a force along the motion grows by ``stiffness_along`` times
    the set-point's lead over the TCP along it, integrated over ``track_feel`` (clipped to
    ``[0, push_force]``: at most the friction of a coefficient 1); 0 (the default) follows
    with the feed-forward alone.
    """

    stiffness_along: float = 1500.0
    stiffness_across: float = 150.0
    stiffness_z: float = 100.0
    stiffness_rot: tuple[float, float, float] = (40.0, 40.0, 40.0)
    push_force: float = 6.0
    aligned: bool = True
    settle_time: float = 1.0
    max_force: float = 80.0
    anchor: str = "frame"
    press_feel: float = 0.0
    hold_depth: float | None = None
    hold_stiffness: float | None = None
    tilt: TiltConfig | None = None
    track_feel: float = 0.0

    def __post_init__(self) -> None:
        for name in (
            "track_feel",
            "stiffness_along",
            "stiffness_across",
            "stiffness_z",
            "push_force",
            "settle_time",
            "max_force",
            "press_feel",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise SkillError(f"follow: {name} must be >= 0, got {value}")
        if self.hold_depth is not None and not (
            math.isfinite(self.hold_depth) and self.hold_depth > 0
        ):
            raise SkillError(f"follow: hold_depth must be > 0, got {self.hold_depth}")
        if self.hold_stiffness is not None and not (
            math.isfinite(self.hold_stiffness) and self.hold_stiffness >= 0
        ):
            raise SkillError(f"follow: hold_stiffness must be >= 0, got {self.hold_stiffness}")
        if self.anchor not in ("frame", "entry"):
            raise SkillError(f"follow: anchor must be 'frame' or 'entry', got {self.anchor!r}")

    @property
    def extra_time(self) -> float:
        """Time (s) the follower may need past ``settle_time``: a tilted search's lateral
        and align phases (0 upright)."""
        return 0.0 if self.tilt is None else self.tilt.extra_time


class Follower:
    """One execution's follower of ``traj`` with ``cfg``: the trajectory's offset (m, task
    frame), the direction of the last motion (x-y; its stiffness is aligned with it), the
    felt-press loop's integral (N), the x-y where the part is held (m; None: not held) and
    the TCP's height when the follower started (m)."""

    def __init__(self, traj: SetpointTrajectory, cfg: FollowConfig) -> None:
        self.traj, self.cfg = traj, cfg
        self.rot_k = np.asarray(cfg.stiffness_rot, dtype=float)
        self.diag = np.array([cfg.stiffness_along] * 2 + [cfg.stiffness_z] + list(self.rot_k))
        self.direction = np.array([1.0, 0.0])
        self.offset = np.zeros(3)
        self.press_correction = 0.0
        self.track_correction = 0.0
        self.hold: np.ndarray | None = None
        self.z0 = 0.0

    def start(self, pc: Percept) -> None:
        """Start following (the set-point in ``pc`` is where the node is entered)."""
        self.direction[:] = (1.0, 0.0)
        self.offset[:] = pc.p_d - self.traj.pos[0] if self.cfg.anchor == "entry" else 0.0
        pc.done = False
        self.press_correction = self.track_correction = 0.0
        self.z0, self.hold = float(pc.p[2]), None

    def track(
        self, pc: Percept, out: MPCommand, t_traj: float, searching: bool = True
    ) -> np.ndarray:
        """The set-point, its velocity and the feed-forward wrench with the push, at time
        ``t_traj`` (s) on the trajectory; returns the trajectory's orientation there.
        ``searching``: a tilted search's searching phase (the lag loop runs there only)."""
        cfg = self.cfg
        pos, quat, vel, ff = self.traj.sample(t_traj)
        pc.p_d[:] = pos + self.offset
        pc.q_d[:] = quat
        if math.hypot(vel[0], vel[1]) > 1e-6:
            self.direction[:] = vel[:2]
        out.twist[:3] = vel
        out.twist[3:] = 0.0
        out.wrench[:] = ff
        out.wrench[2] -= cfg.push_force
        if cfg.press_feel > 0.0:
            wanted = -out.wrench[2]
            if pc.f[2] > 0.5 * wanted:  # pressing on a surface: not over a hole, not in air
                step = (wanted - pc.f[2]) * pc.dt / cfg.press_feel
                lim = 0.5 * cfg.push_force
                self.press_correction = min(lim, max(-lim, self.press_correction + step))
            out.wrench[2] -= self.press_correction
        if cfg.track_feel > 0.0 and searching:
            self._track_loop(pc, out)
        else:
            self.track_correction = 0.0
        return quat

    def _track_loop(self, pc: Percept, out: MPCommand) -> None:
        """``track_feel``'s loop (see :class:`FollowConfig`): the force along the motion."""
        cfg = self.cfg
        u = self.direction / max(1e-12, math.hypot(self.direction[0], self.direction[1]))
        if pc.f[2] > 0.5 * cfg.push_force:  # pressed on a surface: the lag is its friction
            lag = float((pc.p_d[0] - pc.p[0]) * u[0] + (pc.p_d[1] - pc.p[1]) * u[1])
            step = cfg.stiffness_along * lag * pc.dt / cfg.track_feel
            self.track_correction = min(cfg.push_force, max(0.0, self.track_correction + step))
        out.wrench[:2] += self.track_correction * u

    def hold_still(self, pc: Percept, out: MPCommand) -> None:
        """Where the part is held: the x-y set-point stays there, only the push goes on."""
        assert self.hold is not None
        pc.p_d[:2] = self.hold
        out.twist[:2] = 0.0
        out.wrench[:2] = 0.0

    def stiffness(self, out: MPCommand) -> None:
        """Held: ``hold_stiffness`` in every x-y direction; else aligned with the motion."""
        cfg = self.cfg
        if self.hold is not None and cfg.hold_stiffness is not None:
            k = cfg.hold_stiffness
            out.stiffness_full[:] = aligned_stiffness(
                self.direction, k, k, cfg.stiffness_z, self.rot_k
            )
            out.full = True
        elif cfg.aligned:
            out.stiffness_full[:] = aligned_stiffness(
                self.direction, cfg.stiffness_along, cfg.stiffness_across, cfg.stiffness_z,
                self.rot_k,
            )  # fmt: skip
            out.full = True
        else:
            out.stiffness[:] = self.diag
