"""The held part as the firmware's load (``setLoad``): its mass properties and where they sit."""

import mujoco
import numpy as np
import pytest

from teachfit.core.errors import TeachfitError
from teachfit.robot.franka.frames import ee2tcp_for_part
from teachfit.robot.franka.load import PartLoad, part_load
from teachfit.tasks import get_task


@pytest.mark.parametrize("name", ["peg", "socket3d"])
def test_the_load_is_the_part_the_fr3_cell_holds(name: str) -> None:
    """Mass, centre of mass and inertia equal the held part's body in the FR3 cell (the
    twin's physics), taken in the TCP frame."""
    pytest.importorskip("franky_sim", reason="the FR3 cell needs franky-sim's model")
    from teachfit.robot.fr3.model import PART_PREFIX, TCP_SITE, build_fr3_model

    task = get_task(name)
    load = part_load(task)
    model = build_fr3_model(task)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"{PART_PREFIX}held_part")
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, TCP_SITE)
    assert load.mass == pytest.approx(float(model.body_mass[body])) and load.mass > 0.01
    rot = data.site_xmat[site].reshape(3, 3)  # the TCP's axes in the world
    com = rot.T @ (data.xipos[body] - data.site_xpos[site])
    np.testing.assert_allclose(load.com, com, atol=1e-9)
    ximat = data.ximat[body].reshape(3, 3)
    inertia = rot.T @ ximat @ np.diag(model.body_inertia[body]) @ ximat.T @ rot
    np.testing.assert_allclose(load.inertia, inertia, atol=1e-12)


def test_in_the_flange_frame_the_centre_of_mass_is_down_the_flange_axis() -> None:
    """The peg (60 mm) held with its top at EE (0.1034 m down the flange axis, turned -pi/4):
    its centre of mass half its length further down, the inertia turned with it."""
    task = get_task("peg")
    load = part_load(task)
    f_t_ee = np.eye(4)
    f_t_ee[:3, :3] = [
        [np.cos(-np.pi / 4), -np.sin(-np.pi / 4), 0],
        [np.sin(-np.pi / 4), np.cos(-np.pi / 4), 0],
        [0, 0, 1],
    ]
    f_t_ee[2, 3] = 0.1034
    mass, com, inertia = load.in_flange(f_t_ee @ ee2tcp_for_part(0.06).matrix)
    assert mass == pytest.approx(load.mass)
    # the tip 0.1634 m down the flange axis, +z of the TCP back up: the centre 0.03 m above it
    np.testing.assert_allclose(com, [0.0, 0.0, 0.1634 - load.com[2]], atol=1e-9)
    assert load.com[2] == pytest.approx(0.03, abs=1e-4)
    i_f = np.reshape(inertia, (3, 3), order="F")
    np.testing.assert_allclose(i_f, i_f.T, atol=1e-15)
    # a peg: the same about any axis across it, much less about its own (the flange's z)
    assert i_f[0, 0] == pytest.approx(i_f[1, 1]) and i_f[2, 2] < 0.2 * i_f[0, 0]


def test_a_load_with_a_negative_mass_or_a_wrong_shape_is_refused() -> None:
    with pytest.raises(TeachfitError, match="held part's load"):
        PartLoad(-0.1, np.zeros(3), np.eye(3))
    with pytest.raises(TeachfitError, match="held part's load"):
        PartLoad(0.1, np.zeros(2), np.eye(3))
