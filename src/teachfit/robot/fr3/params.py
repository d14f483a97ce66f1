"""Franka Research 3: published limits, identified joint friction, and the simulated arm's settings.

Limits are Franka's datasheet values for the FR3 ("Robot and interface specifications", FCI
documentation): joint position range ``q_min``/``q_max`` (rad), joint speed ``dq_max`` (rad/s),
joint torque ``tau_max`` (N·m) and torque rate ``dtau_max`` (N·m/s), all per joint 1..7.

Joint friction is the identification of Gaz, Cognetti, Oliva, Robuffo Giordano, De Luca,
"Dynamic Identification of the Franka Emika Panda Robot With Retrieval of Feasible Parameters
Using Penalty-Based Optimization", IEEE RA-L 4(4), 2019, eq. (9):

    tau_f,i(dq_i) = phi1_i / (1 + exp(-phi2_i (dq_i + phi3_i))) - phi1_i / (1 + exp(-phi2_i phi3_i))

(N·m). The sigmoid saturates at ``phi1_i (1 - s_i)`` for ``dq_i -> +inf`` and at ``-phi1_i s_i``
for ``dq_i -> -inf`` (``s_i = 1 / (1 + exp(-phi2_i phi3_i))``): a Coulomb level of ``phi1_i / 2``
either way, off-centred by ``phi1_i (1/2 - s_i)`` (at most 0.02 N·m here).

Gaz et al.'s sigmoid is a sliding-friction curve: it passes through zero at rest and has no
static (breakaway) peak, and no Stribeck decay from that peak to the sliding level. The
simulated joints add both, as the steady-state curve of the LuGre model (reference below):

    |tau_f,i(dq_i)| = F_c,i + (F_s,i - F_c,i) exp(-(dq_i / v_s)^2),   F_s,i = r F_c,i

with ``F_c,i = phi1_i / 2`` (Gaz's Coulomb level), a breakaway ratio ``r`` and a Stribeck
velocity ``v_s`` (rad/s, link side); both are :class:`FR3Params` fields (``breakaway_ratio``,
``stribeck_velocity``), and how the arm simulates the curve is in
:mod:`teachfit.robot.fr3.model`. No Franka identification we know of publishes either (Gaz et
al. fit the sliding curve only, from motions away from zero speed), so both are assumptions:
:data:`BREAKAWAY_RATIO` ``= 1.5`` is the ratio of the LuGre paper's friction example (Canudas
de Wit, Olsson, Åström, Lischinsky, "A new model for control of systems with friction", IEEE
TAC 40(3), 1995: ``F_s = 1.5 N`` against ``F_c = 1 N``), and ``v_s = 0.01 rad/s`` puts the
decay at the joint speeds of a search (about 0.02 rad/s at the teacher's 12 mm/s), where
stick-slip lives.

**Off by default** (``breakaway_ratio = 1``: the joints stick and slide at Gaz's level, as
before the peak was modelled): with the static peak the arm's pitch joints, stuck while the
part slides, hold up to ``F_s`` of the open-loop press instead of ``F_c``, and the teacher's
demonstration on peg2d reads f_z with a std of 0.68 N at ``r = 1.5`` (0.53 N at ``r = 1.1``,
0.49 N without; the same 0.68 N as Gaz's friction scaled by 1.5 without a peak, so it is the
level, not the Stribeck dynamics), past the sensor-smoothness goal of 0.5 N
(``benchmarks/sensor_smoothness.py``). ``FR3Params(breakaway_ratio=BREAKAWAY_RATIO)`` (or the
robot option ``breakaway_ratio=1.5``) switches it on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from teachfit.core.errors import ControlError

Vec7 = tuple[float, float, float, float, float, float, float]

#: FR3 joint position limits (rad)
Q_MIN: Vec7 = (-2.7437, -1.7837, -2.9007, -3.0421, -2.8065, 0.5445, -3.0159)
Q_MAX: Vec7 = (2.7437, 1.7837, 2.9007, -0.1518, 2.8065, 4.5169, 3.0159)
#: FR3 joint speed limits (rad/s)
DQ_MAX: Vec7 = (2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26)
#: joint torque limits (N·m)
TAU_MAX: Vec7 = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)
#: torque rate limit (N·m/s), every joint
DTAU_MAX = 1000.0

#: Gaz et al. 2019, Table/eq. (9): friction sigmoid amplitude (N·m), steepness (s/rad), offset
GAZ_PHI1: Vec7 = (0.54615, 0.87224, 0.64068, 1.2794, 0.83904, 0.30301, 0.56489)
GAZ_PHI2: Vec7 = (5.1181, 9.0657, 10.136, 5.5903, 8.3469, 17.133, 10.336)
GAZ_PHI3: Vec7 = (0.039533, 0.025882, -0.04607, 0.036194, 0.026226, -0.021047, 0.0035526)

#: a posture inside the limits with the hand pointing down over the table (Franka's "ready")
READY_Q: Vec7 = (0.0, -0.3, 0.0, -2.2, 0.0, 1.9, 0.7853981633974483)


def gaz_friction(dq: np.ndarray) -> np.ndarray:
    """Gaz et al.'s friction torque ``tau_f(dq)`` (7,) in N·m for joint speeds ``dq`` (rad/s)."""
    p1, p2, p3 = (np.asarray(v) for v in (GAZ_PHI1, GAZ_PHI2, GAZ_PHI3))
    return p1 / (1 + np.exp(-p2 * (np.asarray(dq) + p3))) - p1 / (1 + np.exp(-p2 * p3))


def coulomb_friction() -> np.ndarray:
    """Coulomb level of Gaz et al.'s sigmoid, ``phi1 / 2`` (7,) N·m: the sliding level."""
    return np.asarray(GAZ_PHI1) / 2.0


#: static (breakaway) over sliding friction, ``F_s / F_c`` (Canudas de Wit et al. 1995's example)
BREAKAWAY_RATIO = 1.5
#: Stribeck velocity (rad/s, link side): the static peak decays to the sliding level over it
STRIBECK_VELOCITY = 0.01


SENSORS = ("joint-torques", "wrist-ft")


@dataclass(frozen=True)
class FR3Params:
    """Settings of the simulated FR3 cell (m, rad, s, N, N·m, Hz).

    ``base_pos`` places the arm's base in the task's world frame: 0.5 m behind the hole, on the
    table the fixture stands on, facing +x; the task's cell stays where the task builds it.
    ``mount_offset`` is the distance from the flange to the top of the held part along the
    flange axis (the bottom face of the Franka Hand housing; the fingers are removed and the
    part is rigidly attached). ``sensor`` chooses how the external wrench is measured:
    ``"joint-torques"`` (Franka's ``O_F_ext_hat_K``) or ``"wrist-ft"`` (an F/T sensor at the
    flange). ``wrench_cutoff`` (Hz) is the first-order low-pass of either estimate (the
    momentum observer's gain, the wrist sensor's analogue stage), ``output_cutoff`` (Hz) the
    second-order Butterworth both then pass before anyone reads them (the 100 Hz log's
    anti-alias filter; 18 Hz is one of the ATI Net F/T's options, see
    :mod:`teachfit.robot.sensor_filter`); ``torque_noise`` (N·m) and ``ft_noise`` (N, N·m)
    the white noise per tick of the joint torque sensors and of the wrist sensor's gauges.
    ``null_stiffness`` (N·m/rad) and ``null_damping`` (N·m·s/rad) pull the redundant joint
    motion to the IK posture through the dynamically consistent null-space projector.
    ``visual`` loads the visual meshes (rendering; costs about a second of start-up).

    Contact model (see :mod:`teachfit.robot.fr3.model` for why): ``contact_solref`` and
    ``contact_solimp`` replace the task's ``solref``/``solimp`` (its friction is kept):
    a progressive contact whose impedance rises from ``dmin = 0.05`` at first touch to
    ``dmax = 0.99`` over 0.5 mm, with a 4 ms time constant. ``joint_friction_solref`` is the
    time constant of the gears' dry friction (MuJoCo ``solreffriction`` of the joints).

    Joint friction (see the module docstring): ``joint_friction`` scales Gaz et al.'s Coulomb
    level ``F_c``; the joints break away at ``F_s = breakaway_ratio F_c`` and slide at
    ``F_c + (F_s - F_c) exp(-(dq / stribeck_velocity)^2)`` (N·m, rad/s).
    """

    base_pos: tuple[float, float, float] = (-0.5, 0.0, 0.0)
    mount_offset: float = 0.066
    sensor: str = "joint-torques"
    wrench_cutoff: float = 30.0
    output_cutoff: float = 18.0
    torque_noise: float = 0.02
    ft_noise: tuple[float, float] = (0.05, 0.002)
    null_stiffness: float = 10.0
    null_damping: float = 1.0
    timestep: float = 0.001
    visual: bool = False
    contact_solref: tuple[float, float] = (0.004, 1.0)
    contact_solimp: tuple[float, float, float] = (0.05, 0.99, 0.0005)
    joint_friction_solref: tuple[float, float] = (0.005, 1.0)
    joint_friction: float = 1.0
    breakaway_ratio: float = 1.0
    stribeck_velocity: float = STRIBECK_VELOCITY

    def __post_init__(self) -> None:
        if self.sensor not in SENSORS:
            raise ControlError(f"fr3 sensor must be one of {SENSORS}, got {self.sensor!r}")
        if not self.wrench_cutoff > 0:
            raise ControlError("wrench_cutoff must be > 0 Hz")
        if not 0 < self.output_cutoff < 0.5 / self.timestep:
            raise ControlError("output_cutoff must be within (0 Hz, the physics rate's Nyquist)")
        if self.torque_noise < 0 or min(self.ft_noise) < 0:
            raise ControlError("sensor noise must be >= 0")
        if self.null_stiffness < 0 or self.null_damping < 0:
            raise ControlError("null-space gains must be >= 0")
        if not 0 < self.timestep <= 0.002:
            raise ControlError("timestep must be within (0, 2 ms]")
        if self.contact_solref[0] < 2 * self.timestep or self.joint_friction_solref[0] < (
            2 * self.timestep
        ):
            raise ControlError("solref time constants must be >= 2 timesteps")
        if not 0 < self.contact_solimp[0] <= self.contact_solimp[1] < 1:
            raise ControlError("contact_solimp needs 0 < dmin <= dmax < 1")
        if self.joint_friction < 0:
            raise ControlError("joint_friction must be >= 0")
        if not 1 <= self.breakaway_ratio < float("inf"):
            raise ControlError("breakaway_ratio (static over sliding friction) must be >= 1")
        if not 0 < self.stribeck_velocity < float("inf"):
            raise ControlError("stribeck_velocity must be > 0 rad/s")
        if self.mount_offset < 0:
            raise ControlError("mount_offset must be >= 0")

    def static_friction(self) -> np.ndarray:
        """Breakaway torques ``F_s`` (7,) N·m: the joints' MuJoCo ``frictionloss``."""
        return coulomb_friction() * self.joint_friction * self.breakaway_ratio

    def stribeck(self) -> tuple[np.ndarray, np.ndarray]:
        """The Stribeck term's per-joint constants for the compiled tick: ``F_s - F_c`` (7,)
        N·m and ``1 / v_s`` (7,) s/rad (:func:`teachfit.robot.fr3.kernel.stribeck`)."""
        drop = coulomb_friction() * self.joint_friction * (self.breakaway_ratio - 1.0)
        return drop, np.full(len(drop), 1.0 / self.stribeck_velocity)
