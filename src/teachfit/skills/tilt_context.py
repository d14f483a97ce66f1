"""What the nodes of a tilted search share within one execution: :class:`TiltContext`.

The phases of a tilted search (:mod:`teachfit.skills.tilt`) are nodes of a skill graph
(:mod:`teachfit.skills.tilt_graph`); what has to survive from one node to the next lives
here, typed and documented, created by the search node when the execution enters it first
and published on the percept (``pc.shared[KEY]``), where the other nodes and the
transitions' conditions (:mod:`teachfit.skills.tilt_conditions`) find it. Times are s since
the search started (the *follow time*, :meth:`TiltContext.time`), heights and positions m,
task frame.
"""

from __future__ import annotations

import math

import numpy as np

from teachfit.core.errors import SkillError
from teachfit.core.geometry import quat_mul_into
from teachfit.core.setpoints import SetpointTrajectory
from teachfit.skills.follower import FollowConfig, Follower
from teachfit.skills.percept import MPCommand, Percept
from teachfit.skills.tilt import LEAD_TIME, TILT_SETTLE

#: where a tilted search's context is published on the percept
KEY = "tilt"


class TiltContext:
    """One tilted search's shared state (see the module docstring).

    The follower and the trajectory's clock: ``follower`` (offset, direction, press loop,
    ``hold``: x-y where the align holds the part); ``t_start`` (s since the skill started,
    when the search started); ``paused`` (s the trajectory's clock stood still: it runs only
    while a search node commands, so a search goes on from where the trajectory was left);
    ``t_last`` (follow time of the last command); ``searching`` (a search node gave the last
    command); ``blend``, ``blend_t0``, ``blend_time`` (m, s, s: the x-y offset the set-point
    fades out from a resumed search back to the trajectory, and the lead at the start).

    The tilt: ``d`` (2,): the low rim's side; ``full`` (rad) the tilt searched at now and
    ``q_tilt`` its rotation (it alternates with the retry angle after a missed align).

    The phases' marks: ``t0`` (when the active phase began); ``z_top`` (the reference height
    a drop is felt below); ``z_floor`` (where a missed align stood upright: the reference
    while the part settles tilted again); ``origin`` (x-y where the slide to the wall started,
    from where a drop was felt; after a lift: the top's edge); ``z_aligned`` (the height when
    the part came upright); the lift's course: ``z_fall``, ``xy_fall`` (where the part fell
    off the top), ``z_lift`` (the set-point's height once up), ``t_lifted``, ``xy_lifted``
    (when and where it was up), ``back`` (x-y the lift returns to: where the trajectory was
    left), ``arrived`` (the set-point is there).
    """

    def __init__(self, traj: SetpointTrajectory, cfg: FollowConfig, pc: Percept) -> None:
        tilt = cfg.tilt
        if tilt is None:
            raise SkillError("a tilted search needs a follow config with a tilt")
        self.traj, self.cfg = traj, tilt
        self.follower = Follower(traj, cfg)
        self.d = tilt.unit(traj.pos)
        self.t_start = pc.t
        self.paused, self.t_last, self.searching = 0.0, 0.0, True
        self.blend = np.zeros(2)
        self.blend_t0, self.blend_time = 0.0, 0.0
        self.full, self.q_tilt = 0.0, np.zeros(4)
        self.tilt_to(tilt.angle)
        z = float(pc.p[2])
        self.t0, self.z_top, self.z_floor, self.z_aligned = 0.0, z, -math.inf, z
        self.origin = np.zeros(2)
        self.z_fall, self.z_lift, self.t_lifted = z, z, 0.0
        self.xy_fall, self.xy_lifted, self.back = np.zeros(2), np.zeros(2), np.zeros(2)
        self.arrived = False

    def start(self, pc: Percept) -> None:
        """The search begins (``pc``'s set-point is where it is entered)."""
        self.follower.start(pc)
        if self.cfg.lead > 0.0:  # the low rim follows the path
            shift = self.cfg.lead * self.d
            self.follower.offset[:2] -= shift
            self.blend[:] = shift  # from where the part is, back by the lead over LEAD_TIME
            self.blend_t0, self.blend_time = self.time(pc), LEAD_TIME
        self.set_goal(pc)

    def set_goal(self, pc: Percept) -> None:
        """The goal every node heads for: the trajectory's end."""
        pc.goal[:] = self.traj.pos[-1] + self.follower.offset

    # ------------------------------------------------------------------ the trajectory
    def time(self, pc: Percept) -> float:
        """The follow time (s since the search started)."""
        return pc.t - self.t_start

    def planned_xy(self, pc: Percept) -> np.ndarray:
        """The x-y set-point (2,) the trajectory gives now (with the blend), as
        :meth:`track` sets it."""
        t = self.time(pc)
        xy = self.traj.sample(t - self.paused)[0][:2] + self.follower.offset[:2]
        if t - self.blend_t0 < self.blend_time:
            xy += self.blend * (1.0 - (t - self.blend_t0) / self.blend_time)
        return xy

    def track(self, pc: Percept, out: MPCommand, searching: bool) -> tuple[np.ndarray, float]:
        """Follow the trajectory at its clock: the set-point (with the blend), velocity,
        feed-forward and push; returns the trajectory's orientation and time there."""
        t = self.time(pc)
        t_traj = t - self.paused
        quat = self.follower.track(pc, out, t_traj, searching)
        if t - self.blend_t0 < self.blend_time:
            pc.p_d[:2] += self.blend * (1.0 - (t - self.blend_t0) / self.blend_time)
        return quat, t_traj

    def tick(self, pc: Percept, searching: bool) -> None:
        """Advance the trajectory's clock past this command (it stood still since the last
        one unless a search node gave it), then note whether this node searches; a search
        resumed now goes on from where the part is and blends back to the trajectory."""
        t = self.time(pc)
        elapsed, self.t_last = t - self.t_last, t
        if not self.searching:
            self.paused += elapsed
        if searching and not self.searching:
            self.follower.hold = None
            self.blend[:] = pc.p[:2] - pc.p_d[:2]
            self.blend_t0 = t
            self.blend_time = max(0.2, float(np.hypot(*self.blend)) / self.cfg.lateral_speed)
            pc.p_d[:2] = pc.p[:2]
        self.searching = searching

    # ------------------------------------------------------------------------- the tilt
    def tilt_to(self, angle: float) -> None:
        """Search at ``angle`` (rad) from now on."""
        self.full = angle
        self.q_tilt = self.about_axis(angle)

    def about_axis(self, angle: float) -> np.ndarray:
        """The rotation by ``angle`` (rad) about z x d = (-d_y, d_x, 0): lowers the +d rim."""
        s = math.sin(0.5 * angle)
        return np.array([math.cos(0.5 * angle), -self.d[1] * s, self.d[0] * s, 0.0])

    def orient(self, pc: Percept, quat: np.ndarray, angle: float) -> None:
        """The orientation set-point: ``quat`` tilted by ``angle`` (rad) about z x d."""
        if angle >= self.full:
            quat_mul_into(pc.q_d, self.q_tilt, quat)
        elif angle > 0.0:
            quat_mul_into(pc.q_d, self.about_axis(angle), quat)
        else:
            pc.q_d[:] = quat

    # ---------------------------------------------------------------------- the search
    def reference(self, pc: Percept) -> float:
        """The tilted search's reference height with this tick's TCP height: the highest
        since the tilt settled; while it settles never below ``z_floor``."""
        z = float(pc.p[2])
        z_top = self.z_top
        if self.time(pc) - self.t0 < TILT_SETTLE:  # still tilting: no resting height yet,
            z_top = max(z, self.z_floor)  # but below the edge it stood on: a drop
        return max(z_top, z)


def context_of(pc: Percept) -> TiltContext:
    """The tilted search's context of this execution (published by its search node)."""
    ctx = pc.shared.get(KEY)
    if not isinstance(ctx, TiltContext):
        raise SkillError("a tilted search's phase or condition runs only inside its graph")
    return ctx
