"""The per-tick conversions of the Franka driver on real pylibfranka states and model."""

from __future__ import annotations

import numpy as np
import pytest

pf = pytest.importorskip("pylibfranka", reason="needs the franka extra (pylibfranka)")

from teachfit.core.errors import ConnectionLost, LimitViolation, ReflexFault, RobotFault  # noqa: E402
from teachfit.robot.franka import FrankaFrames, FrankaLimits, ee2tcp_for_part  # noqa: E402
from teachfit.robot.franka import kernel as k  # noqa: E402
from teachfit.robot.franka.loop import fault_from  # noqa: E402
from teachfit.robot.franka.tick import TorqueTick  # noqa: E402


@pytest.fixture
def state_and_model(franka_sim: object) -> tuple[object, object]:
    robot = pf.Robot("127.0.0.1", pf.RealtimeConfig.kIgnore)
    return robot.read_once(), robot.load_model()


def test_measured_wrench_is_the_environments_on_the_tool_at_the_tcp(
    state_and_model: tuple[object, object],
) -> None:
    state, model = state_and_model
    tick = TorqueTick(FrankaFrames(ee2tcp=ee2tcp_for_part(0.05)), FrankaLimits())
    # libfranka: the robot pushes the environment along -x (and twists it about -z) at K = EE
    state.O_F_ext_hat_K = [-4.0, 0.0, 0.0, 0.0, 0.0, -0.3]  # type: ignore[attr-defined]
    tick.kinematics(state, model)
    w = tick.raw_wrench()
    o_t_ee = np.asarray(state.O_T_EE).reshape(4, 4, order="F")  # type: ignore[attr-defined]
    lever = o_t_ee[:3, :3] @ np.array([0.0, 0.0, -0.05])  # TCP -> EE (base = world rotation)
    np.testing.assert_allclose(w[:3], [4.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(w[3:], [0.0, 0.0, 0.3] + np.cross(lever, [4.0, 0.0, 0.0]), atol=1e-6)


def test_tcp_jacobian_moves_the_point_with_the_lever(
    state_and_model: tuple[object, object],
) -> None:
    state, model = state_and_model
    near = TorqueTick(FrankaFrames(ee2tcp=ee2tcp_for_part(0.0)), FrankaLimits())
    far = TorqueTick(FrankaFrames(ee2tcp=ee2tcp_for_part(0.2)), FrankaLimits())
    near.kinematics(state, model)
    far.kinematics(state, model)
    lever = far.pos - near.pos
    assert np.linalg.norm(lever) == pytest.approx(0.2, abs=1e-6)
    # same angular rows; linear rows differ by w x lever (v_far = v_near + w x lever)
    np.testing.assert_allclose(far.jacobian[3:], near.jacobian[3:])
    for col in range(7):
        w = near.jacobian[3:, col]
        np.testing.assert_allclose(
            far.jacobian[:3, col], near.jacobian[:3, col] + np.cross(w, lever), atol=1e-9
        )


def test_first_torques_are_rate_limited(state_and_model: tuple[object, object]) -> None:
    from teachfit.control import make_law
    from teachfit.core.control import FixedGainSpec
    from teachfit.core.geometry import Pose
    from teachfit.core.state import ImpedanceCommand

    state, model = state_and_model
    tick = TorqueTick(FrankaFrames(), FrankaLimits())
    tick.kinematics(state, model)
    law = make_law(FixedGainSpec(), np.ones(6), 0.001)
    far = Pose(tick.pos + np.array([0.05, 0.0, 0.0]), tick.quat.copy())
    law.set_command(ImpedanceCommand.hold(far, stiffness=3000.0), 0.0)
    tau = tick.torques(0.001, law, state, model)
    assert np.abs(tau).max() == pytest.approx(1.0)  # 1000 N·m/s for 1 ms from zero
    assert np.linalg.norm(tick.wrench_cmd[:3]) == pytest.approx(60.0)  # clipped to max_force


def test_libfranka_exceptions_become_typed_faults() -> None:
    reflex = fault_from(pf.ControlException("libfranka: Move command aborted: cartesian_reflex"))
    assert type(reflex) is ReflexFault
    limit = fault_from(pf.ControlException("aborted: joint_velocity_violation"))
    assert type(limit) is LimitViolation
    assert (
        type(fault_from(pf.NetworkException("libfranka: UDP receive: Timeout"))) is ConnectionLost
    )
    assert type(fault_from(ValueError("bad"))) is RobotFault


def test_operational_mass_is_lambdas_diagonal_in_world_axes() -> None:
    from teachfit.robot.franka.tick import operational_mass

    rng = np.random.default_rng(3)
    jac = rng.normal(size=(6, 7))
    a = rng.normal(size=(7, 7))
    mass = a @ a.T + 7 * np.eye(7)
    lam = np.linalg.inv(jac @ np.linalg.inv(mass) @ jac.T)
    np.testing.assert_allclose(operational_mass(mass, jac, np.eye(3)), np.diag(lam))
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # about z
    turned = operational_mass(mass, jac, quarter)
    np.testing.assert_allclose(turned[[1, 0, 2, 4, 3, 5]], np.diag(lam))  # x and y swap


def test_operational_inertia_is_the_full_lambda_in_world_axes() -> None:
    from teachfit.robot.franka.tick import operational_inertia

    rng = np.random.default_rng(4)
    jac = rng.normal(size=(6, 7))
    a = rng.normal(size=(7, 7))
    mass = a @ a.T + 7 * np.eye(7)
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # about z
    lam = operational_inertia(mass, jac, quarter)
    rot = np.kron(np.eye(2), quarter)
    # the world wrench lam @ acc accelerates the TCP by acc: J M^-1 J^T (world) undoes it
    acc = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    mobility = rot @ jac @ np.linalg.solve(mass, jac.T) @ rot.T
    np.testing.assert_allclose(mobility @ lam @ acc, acc, atol=1e-9)
    np.testing.assert_allclose(lam, lam.T)
    # not diagonal: accelerating along z alone takes force along x and y too
    assert np.count_nonzero(np.abs(lam[:3, 2]) > 1e-6) == 3


@pytest.mark.parametrize("adaptive", [False, True])
def test_the_compiled_tick_gives_the_python_laws_torques(
    state_and_model: tuple[object, object], adaptive: bool
) -> None:
    from teachfit.control import make_law
    from teachfit.core.control import AdaptiveSpec, FixedGainSpec
    from teachfit.core.geometry import Pose
    from teachfit.core.state import ImpedanceCommand

    state, model = state_and_model
    frames, mass = FrankaFrames(ee2tcp=ee2tcp_for_part(0.05)), np.array([3, 3, 3, 0.1, 0.1, 0.1])
    ticks = [TorqueTick(frames, FrankaLimits()) for _ in range(2)]
    spec = AdaptiveSpec() if adaptive else FixedGainSpec()
    laws = [make_law(spec, mass, 0.001) for _ in range(2)]
    ticks[0].kinematics(state, model)
    near = Pose(ticks[0].pos + [0.004, -0.002, 0.003], ticks[0].quat.copy())
    # a moving set-point that expires between commands: extrapolation, spin and expiry
    cmd = ImpedanceCommand.hold(
        near, stiffness=[800, 800, 800, 30, 30, 30], lin_vel=[0.02, 0.0, -0.01],
        ang_vel=[0.0, 0.0, 0.3], expires_after=0.006,
    )  # fmt: skip
    rng = np.random.default_rng(3)
    dq0, ext0 = np.asarray(state.dq), np.asarray(state.O_F_ext_hat_K)  # type: ignore[attr-defined]
    for n in range(40):
        state.dq = (dq0 + rng.normal(0.0, 0.05, 7)).tolist()  # type: ignore[attr-defined]
        state.O_F_ext_hat_K = (ext0 + rng.normal(0.0, 2.0, 6)).tolist()  # type: ignore[attr-defined]
        t = 0.001 * (n + 1)
        if n % 10 == 0:
            ticks[0].command(laws[0], cmd, t)  # the compiled law's clock is in the tick
            laws[1].set_command(cmd, t)
        assert ticks[0].step(t, laws[0], state, model) == ""
        ticks[1].kinematics(state, model)
        python = ticks[1].torques(t, laws[1], state, model)
        np.testing.assert_allclose(ticks[0].tau, python, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(laws[0].last_wrench, laws[1].last_wrench, atol=1e-9)
    assert np.abs(ticks[0].tau).max() > 1.0  # the rate limit let the torques grow
    # compiled when the tick was made, for the types the loop passes: never on the loop's thread
    assert len(k.tick_at.signatures) == 1 and len(k.torques_at.signatures) == 1
    if adaptive:
        np.testing.assert_allclose(laws[0].feedforward, laws[1].feedforward, atol=1e-12)
        assert np.abs(laws[0].feedforward).max() > 0.0


def test_a_tick_over_the_speed_limit_computes_no_torques_and_says_why(
    state_and_model: tuple[object, object],
) -> None:
    from teachfit.control import make_law
    from teachfit.core.control import FixedGainSpec
    from teachfit.core.state import ImpedanceCommand

    state, model = state_and_model
    tick = TorqueTick(FrankaFrames(), FrankaLimits(max_tcp_speed=0.1))
    tick.kinematics(state, model)
    law = make_law(FixedGainSpec(), np.ones(6), 0.001)
    tick.command(law, ImpedanceCommand.hold(tick_pose(tick)), 0.0)
    state.dq = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5]  # type: ignore[attr-defined]
    assert tick.step(0.001, law, state, model) == ""  # the last joint turns the flange
    before = tick.tau.copy()
    state.dq = [0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0]  # type: ignore[attr-defined]
    assert tick.step(0.002, law, state, model).startswith("TCP speed")
    np.testing.assert_array_equal(tick.tau, before)
    np.testing.assert_array_equal(tick.tau_prev, before)


def tick_pose(tick: TorqueTick) -> object:
    from teachfit.core.geometry import Pose

    return Pose(tick.pos.copy(), tick.quat.copy())
