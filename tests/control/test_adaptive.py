"""Adaptive impedance controller: convergence, stiffening, forgetting, limits, bounds."""

from __future__ import annotations

import numpy as np
import pytest

from teachfit.control.adaptive import (
    AdaptiveImpedance,
    AdaptiveLimits,
    AdaptiveParams,
    meta_bounds,
)
from teachfit.control.base import Controller
from teachfit.core.control import AdaptiveSpec, FixedGainSpec, ImpedanceLimits
from teachfit.core.errors import ControlError
from teachfit.core.state import ImpedanceCommand
from teachfit.robot.floating import FloatingToolParams, FloatingToolRobot
from teachfit.tasks import get_task

MASS = np.array([1.0, 1.0, 1.0, 0.004, 0.004, 0.004])
E_MAX = (0.01,) * 3 + (0.1,) * 3
DE_MAX = (0.1,) * 3 + (1.0,) * 3
Q0 = np.array([1.0, 0.0, 0.0, 0.0])
Z3 = np.zeros(3)


def _hold(stiffness: object = (500.0,) * 3 + (50.0,) * 3) -> ImpedanceCommand:
    return ImpedanceCommand(pos=np.zeros(3), stiffness=stiffness)


def _free_space_error(
    controller: object, force: np.ndarray, ticks: int
) -> tuple[np.ndarray, object]:
    """Hold a pose in free space against a constant external force; the final offset and the
    law that ran."""
    task = get_task("peg2d")
    robot = FloatingToolRobot(
        task, controller=controller, params=FloatingToolParams(ft_noise=(0.0, 0.0))
    )
    start = task.contact_pose([0.05, 0.0]).translated([0, 0, 0.05])
    robot.reset(start)
    robot.data.xfrc_applied[robot._body, :3] = force  # a constant disturbance at the tool's COM
    state = robot.step(ticks)
    return state.pos - start.pos, robot.law


def test_is_a_controller_and_runs_on_the_floating_tool() -> None:
    offset, law = _free_space_error(AdaptiveSpec(), np.zeros(3), 200)
    assert isinstance(law, AdaptiveImpedance) and isinstance(law, Controller)
    assert np.linalg.norm(offset) < 1e-6


def test_feedforward_converges_to_cancel_a_constant_disturbance() -> None:
    force = np.array([5.0, -3.0, 2.0])
    params = AdaptiveParams(gamma_a=(0.0,) * 3 + (1e-2,) * 3)
    offset, ctrl = _free_space_error(AdaptiveSpec(params=params), force, 3000)
    assert ctrl.feedforward[:3] == pytest.approx(-force, abs=0.05)
    fixed, _ = _free_space_error(FixedGainSpec(), force, 3000)
    assert np.linalg.norm(fixed) > 5e-3  # F / K with K = 1000 N/m
    assert np.linalg.norm(offset) < 0.02 * np.linalg.norm(fixed)


def test_forgetting_leaves_the_predicted_equilibrium() -> None:
    """With gamma_a > 0 the fixed point is F_ff = eps / gamma_a = kappa e / gamma_a."""
    ctrl = AdaptiveImpedance(MASS, params=AdaptiveParams(beta=0.0, gamma_a=1e-3))
    ctrl.set_command(_hold(), 0.0)
    e = np.array([0.002, 0.0, 0.0])
    for _ in range(20000):
        ctrl.compute(0.0, -e, Q0, Z3, Z3)
    assert ctrl.feedforward[0] == pytest.approx(10.0 * 0.002 / 1e-3, rel=1e-3)


def test_stiffness_rises_under_persistent_error_and_decays_by_forgetting() -> None:
    p = AdaptiveParams()
    ctrl = AdaptiveImpedance(MASS, params=p)
    ctrl.set_command(_hold(), 0.0)
    k_floor = ctrl.stiffness.copy()
    ks = []
    for _ in range(500):
        ctrl.compute(0.0, np.array([0.004, -0.004, 0.0]), Q0, Z3, Z3)
        ks.append(ctrl.stiffness_adapt[:2])
    ks_arr = np.array(ks)
    assert np.all(np.diff(ks_arr, axis=0) > 0)  # monotone rise on both loaded axes
    assert ks_arr[-1, 0] > 100.0
    assert ctrl.stiffness_adapt[2:] == pytest.approx(np.zeros(4))  # no error, no stiffening
    damp_stiff = ctrl.damping[0]
    k_peak = ctrl.stiffness_adapt
    n = 300
    for _ in range(n):
        ctrl.compute(0.0, np.zeros(3), Q0, Z3, Z3)
    decay = (1.0 - np.array(p.beta) * np.array(p.gamma_b)) ** n
    assert ctrl.stiffness_adapt == pytest.approx(k_peak * decay, rel=1e-9)
    assert np.all(ctrl.stiffness >= k_floor)  # the command's stiffness is the floor
    assert ctrl.damping[0] < damp_stiff  # damping follows stiffness
    ctrl.reset()
    assert np.all(ctrl.stiffness_adapt == 0.0) and np.all(ctrl.feedforward == 0.0)


def test_limits_hold_every_tick_for_random_inputs() -> None:
    rng = np.random.default_rng(7)
    lim = AdaptiveLimits()
    ilim = ImpedanceLimits()
    bounds = meta_bounds(lim, 1e-3, E_MAX, DE_MAX)
    for _ in range(20):
        # meta-parameters up to 100x their bounds, so that every clip is exercised
        scale = rng.uniform(0, 100, size=(4, 6))
        alpha = np.array(bounds.alpha) * scale[0]
        beta = np.array(bounds.beta) * scale[1]
        params = AdaptiveParams(
            alpha=alpha,
            beta=beta,
            gamma_a=np.minimum(np.array(bounds.gamma_a) * scale[2], 0.99 / np.maximum(alpha, 1e-9)),
            gamma_b=np.minimum(np.array(bounds.gamma_b) * scale[3], 0.99 / np.maximum(beta, 1e-9)),
        )
        ctrl = AdaptiveImpedance(MASS, params=params, limits=lim, impedance_limits=ilim)
        k_cmd = rng.uniform(0, 1, 6) * np.array(lim.k_max)
        ctrl.set_command(ImpedanceCommand(pos=np.zeros(3), stiffness=k_cmd), 0.0)
        ff_prev, ka_prev = ctrl.feedforward, ctrl.stiffness_adapt
        for tick in range(200):
            if tick % 50 == 0:  # a new set-point now and then; adaptation carries over
                k_cmd = rng.uniform(0, 1, 6) * np.array(lim.k_max)
                ctrl.set_command(
                    ImpedanceCommand(pos=rng.normal(0, 0.02, 3), stiffness=k_cmd), tick * 1e-3
                )
                # the command may cut K_a to fit under k_max; rate limits apply to adaptation
                ka_prev = np.minimum(ka_prev, np.array(lim.k_max) - k_cmd)
            q = rng.normal(size=4)
            w = ctrl.compute(
                tick * 1e-3, rng.normal(0, 0.05, 3), q / np.linalg.norm(q),
                rng.normal(0, 0.5, 3), rng.normal(0, 3, 3),
            )  # fmt: skip
            ff, k, ka = ctrl.feedforward, ctrl.stiffness, ctrl.stiffness_adapt
            assert np.all(np.abs(ff) <= np.array(lim.f_max) + 1e-12)
            assert np.all(np.abs(ff - ff_prev) <= np.array(lim.df_max) * 1e-3 + 1e-12)
            assert np.all(k <= np.array(lim.k_max) + 1e-9)
            assert np.all(k >= k_cmd - 1e-9)
            assert np.all(np.abs(ka - ka_prev) <= np.array(lim.dk_max) * 1e-3 + 1e-9)
            assert np.linalg.norm(w[:3]) <= ilim.max_force + 1e-9
            assert np.linalg.norm(w[3:]) <= ilim.max_torque + 1e-9
            assert np.all(np.isfinite(w))
            ff_prev, ka_prev = ff, ka


def test_meta_bounds_follow_from_the_limits() -> None:
    lim = AdaptiveLimits(k_max=2000.0, dk_max=1e4, f_max=10.0, df_max=200.0)
    b = meta_bounds(lim, 1e-3, e_max=0.01, de_max=0.1, kappa=10.0)
    eps = 0.1 + 10.0 * 0.01
    assert b.alpha[0] == pytest.approx(200.0 * 1e-3 / eps)
    assert b.beta[0] == pytest.approx(1e4 * 1e-3 / (eps * 0.01))
    assert b.gamma_a[0] == pytest.approx(eps / 10.0)
    assert b.gamma_b[0] == pytest.approx(eps * 0.01 / 2000.0)
    # at the bounds a worst-case step exactly meets the rate limits, forgetting included
    assert b.alpha[0] * eps == pytest.approx(lim.df_max[0] * 1e-3)
    assert b.beta[0] * eps * 0.01 == pytest.approx(lim.dk_max[0] * 1e-3)
    assert b.beta[0] * b.gamma_b[0] * lim.k_max[0] == pytest.approx(lim.dk_max[0] * 1e-3)
    assert b.alpha[0] * b.gamma_a[0] * lim.f_max[0] == pytest.approx(lim.df_max[0] * 1e-3)
    assert meta_bounds(AdaptiveLimits(), 1e-3, E_MAX, DE_MAX).contains(AdaptiveParams())
    assert not b.contains(AdaptiveParams(alpha=2 * b.alpha[0]))
    with pytest.raises(ControlError):
        meta_bounds(lim, 0.0, 0.01, 0.1)
    with pytest.raises(ControlError):
        meta_bounds(lim, 1e-3, 0.0, 0.1)


def test_invalid_construction_and_commands_raise() -> None:
    with pytest.raises(ControlError):
        AdaptiveParams(alpha=-1.0)
    with pytest.raises(ControlError):
        AdaptiveParams(beta=[1.0, 2.0])
    with pytest.raises(ControlError):
        AdaptiveLimits(k_max=0.0)
    with pytest.raises(ControlError):
        AdaptiveImpedance(MASS, params=AdaptiveParams(alpha=2.0, gamma_a=0.5))
    with pytest.raises(ControlError):
        AdaptiveImpedance(np.ones(5))
    ctrl = AdaptiveImpedance(MASS)
    with pytest.raises(ControlError):
        ctrl.compute(0.0, Z3, Q0, Z3, Z3)
    with pytest.raises(ControlError):
        ctrl.set_command(_hold(5000.0), 0.0)  # > k_max
