"""The FR3's joint friction: a joint sticks up to the static level, then slides at Gaz's level."""

import mujoco
import numpy as np
import pytest

from teachfit.core.errors import ControlError
from teachfit.robot.fr3 import FR3Params, kernel
from teachfit.robot.fr3.model import JOINT_TORQUE_SENSORS, build_fr3_model
from teachfit.robot.fr3.params import GAZ_PHI1, READY_Q
from teachfit.tasks import get_task

#: the breakaway ratio tested: Canudas de Wit et al.'s example (the module docstring of params)
RATIO = 1.5
#: a joint "moves" above this speed (rad/s); below it the soft dry friction creeps (<= 2 mrad/s)
MOVING = 0.005


def free_cell(params):
    """The FR3 cell without gravity: one joint against its friction alone."""
    model = build_fr3_model(get_task("peg2d"), params)
    model.opt.gravity[:] = 0.0
    return params, model


@pytest.fixture(scope="module")
def cell():
    return free_cell(FR3Params(breakaway_ratio=RATIO))


def ramp(params, model, joint, seconds=5.0):
    """A joint torque rising by ``F_s / 4`` per second until the joint moves, then held:
    ``(torque at breakaway (N·m), top speed while the torque was below 0.9 F_s (rad/s), rows
    of (friction (N·m), speed (rad/s), joint torque sensor minus the link-side torque (N·m))
    for each tick after)``. Friction = the dry-friction constraint + the Stribeck term."""
    d = mujoco.MjData(model)
    d.qpos[:] = READY_Q
    mujoco.mj_forward(model, d)
    dat, joints = kernel.data_views(d, 0), (np.zeros(0),) * 3 + params.stribeck()
    rate = params.static_friction()[joint] / 4 * model.opt.timestep
    sensor = model.sensor_adr[model.sensor(JOINT_TORQUE_SENSORS[joint]).id]
    broke, stuck_speed, after = None, 0.0, []
    for k in range(int(seconds / model.opt.timestep)):
        if broke is None:
            d.qfrc_applied[joint] = rate * k
        start = abs(d.qvel[joint])  # the speed the step's friction answers
        kernel.step_physics(kernel.routines(), model._address, d._address, dat, joints)
        if broke is not None:
            friction = d.qfrc_constraint[joint] + d.qfrc_passive[joint]
            # the link-side torque sensor: the applied torque past the friction and the rotor
            link = d.qfrc_applied[joint] + friction - model.dof_armature[joint] * d.qacc[joint]
            sensed = d.sensordata[sensor : sensor + 3] @ model.jnt_axis[joint]
            after.append((friction, start, sensed - link))
        speed = abs(d.qvel[joint])
        if broke is None and speed > MOVING:
            broke = float(d.qfrc_applied[joint])
        if broke is None and rate * k < 0.9 * params.static_friction()[joint]:
            stuck_speed = max(stuck_speed, speed)
    assert broke is not None, "the joint never moved"
    return broke, stuck_speed, np.array(after)


@pytest.mark.parametrize("joint", [3, 6])
def test_a_joint_breaks_away_at_the_static_level_and_slides_at_the_coulomb_level(cell, joint):
    params, model = cell
    f_c = GAZ_PHI1[joint] / 2  # Gaz et al.'s Coulomb level
    f_s = RATIO * f_c
    broke, stuck_speed, after = ramp(params, model, joint)
    assert stuck_speed < MOVING / 2  # it sticks (the soft constraint's creep only) up to 0.9 F_s
    assert 0.98 * f_s < broke < 1.05 * f_s  # it breaks away at the static level
    friction, speed = -after[:, 0], after[:, 1]
    # the joint torque sensor reads past the gears' friction, the Stribeck term included
    np.testing.assert_allclose(after[:, 2], 0.0, atol=1e-9)
    sliding = speed > 5 * params.stribeck_velocity
    assert sliding.sum() > 100
    np.testing.assert_allclose(friction[sliding], f_c, rtol=0.01)  # then slides at F_c
    # in between, the Stribeck curve: between the two levels, falling with the speed
    mid = (speed > 0.5 * params.stribeck_velocity) & (speed < 2 * params.stribeck_velocity)
    assert mid.any() and np.all((friction[mid] > f_c) & (friction[mid] < f_s))
    expected = f_c + (f_s - f_c) * np.exp(-((speed[mid] / params.stribeck_velocity) ** 2))
    np.testing.assert_allclose(friction[mid], expected, rtol=0.02)


def test_without_a_static_peak_it_breaks_away_at_the_coulomb_level():
    broke, _, _ = ramp(*free_cell(FR3Params(breakaway_ratio=1.0)), 6)
    assert broke < 1.05 * GAZ_PHI1[6] / 2


@pytest.mark.parametrize(("field", "value"), [("breakaway_ratio", 0.9), ("stribeck_velocity", 0.0)])
def test_friction_settings_are_checked(field, value):
    with pytest.raises(ControlError, match=field):
        FR3Params(**{field: value})
