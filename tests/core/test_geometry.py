"""The geometry kernel against scipy on seeded random quaternions, and Pose round trips."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from teachfit.core.errors import TeachfitError
from teachfit.core.geometry import (
    Pose,
    array_to_poses,
    poses_to_array,
    poses_to_matrices,
    quat_angle,
    quat_conj_into,
    quat_diff_into,
    quat_from_rz,
    quat_integrate_into,
    quat_mul_into,
    quat_normalize_into,
    quat_rotate_into,
    quat_to_matrix_into,
    quat_to_rotvec_into,
    rotation_to_wxyz,
    rz_from_quat,
    wxyz_to_rotation,
    yaw_of,
)

N = 50


@pytest.fixture
def rots():
    return Rotation.random(N, random_state=np.random.default_rng(7))


def _same_rotation(qa: np.ndarray, qb: np.ndarray, atol: float = 1e-12) -> bool:
    """Unit quaternions equal up to sign."""
    return abs(abs(float(np.dot(qa, qb))) - 1.0) < atol


def test_wxyz_order_and_canonical_sign(rots):
    q = rotation_to_wxyz(rots)
    assert np.all(q[:, 0] >= 0)
    raw = rotation_to_wxyz(rots, canonical=False)
    assert np.array_equal(raw, rots.as_quat()[:, [3, 0, 1, 2]])
    assert np.array_equal(q, raw * np.where(raw[:, :1] < 0, -1.0, 1.0))
    assert np.allclose(wxyz_to_rotation(raw).as_matrix(), rots.as_matrix(), atol=1e-14)


def test_product_conjugate_rotation_match_scipy(rots):
    q = rotation_to_wxyz(rots)
    rng = np.random.default_rng(3)
    out = np.zeros(4)
    v_out = np.zeros(3)
    for i in range(N - 1):
        quat_mul_into(out, q[i], q[i + 1])
        assert _same_rotation(out, rotation_to_wxyz(rots[i] * rots[i + 1]))
        quat_conj_into(out, q[i])
        assert _same_rotation(out, rotation_to_wxyz(rots[i].inv()))
        v = rng.normal(size=3)
        quat_rotate_into(v_out, q[i], v)
        assert np.allclose(v_out, rots[i].apply(v), atol=1e-12)


def test_difference_integration_rotvec_match_scipy(rots):
    q = rotation_to_wxyz(rots)
    r = np.zeros(3)
    for i in range(N - 1):
        # qb ⊗ exp(r) = qa, r in qb's own frame
        quat_diff_into(r, q[i], q[i + 1])
        assert np.allclose(r, (rots[i + 1].inv() * rots[i]).as_rotvec(), atol=1e-9)
        quat_to_rotvec_into(r, q[i])
        assert (
            _same_rotation(rotation_to_wxyz(Rotation.from_rotvec(r)), q[i], atol=1e-9)
            and np.linalg.norm(r) <= np.pi + 1e-9
        )
    omega, dt = np.array([0.3, -1.2, 2.0]), 0.01
    for i in range(N):
        qi = q[i].copy()
        quat_integrate_into(qi, omega, dt)
        assert _same_rotation(qi, rotation_to_wxyz(rots[i] * Rotation.from_rotvec(omega * dt)))


def test_matrix_and_normalisation_match_scipy(rots):
    q = rotation_to_wxyz(rots)
    out = np.zeros(9)
    for i in range(N):
        quat_to_matrix_into(out, q[i])
        assert np.allclose(out.reshape(3, 3), rots[i].as_matrix(), atol=1e-14)
        scaled = 3.5 * q[i]
        assert quat_normalize_into(scaled) == pytest.approx(3.5)
        assert np.allclose(scaled, q[i], atol=1e-15)
    assert np.allclose(
        poses_to_matrices([Pose(np.zeros(3), qi) for qi in q])[:, :3, :3],
        rots.as_matrix(),
        atol=1e-14,
    )


def test_pose_compose_inverse_round_trips(rots):
    rng = np.random.default_rng(11)
    poses = [Pose(rng.normal(size=3), rotation_to_wxyz(r)) for r in rots]
    for a, b in zip(poses[:-1], poses[1:], strict=True):
        ab = a.compose(b)
        assert np.allclose(ab.matrix, a.matrix @ b.matrix, atol=1e-12)
        back = ab.compose(b.inverse())
        assert np.allclose(back.pos, a.pos, atol=1e-12) and _same_rotation(back.quat, a.quat)
        ident = a.compose(a.inverse())
        assert np.allclose(ident.pos, 0.0, atol=1e-12) and _same_rotation(ident.quat, [1, 0, 0, 0])
        m = Pose.from_matrix(a.matrix)
        assert np.allclose(m.pos, a.pos) and _same_rotation(m.quat, a.quat)


def test_array_pose_round_trip_and_shape_errors(rots):
    rng = np.random.default_rng(5)
    states = np.concatenate([rng.normal(size=(N, 3)), rotation_to_wxyz(rots)], axis=1)
    poses = array_to_poses(states)
    assert len(poses) == N and all(isinstance(p, Pose) for p in poses)
    assert np.allclose(poses_to_array(poses), states, atol=1e-15)
    assert np.array_equal(Pose.from_array(states[4]).as_array(), poses[4].as_array())
    assert poses_to_array(()).shape == (0, 7) and array_to_poses(np.empty((0, 7))) == ()
    with pytest.raises(TeachfitError, match=r"\(N, 7\)"):
        array_to_poses(states[:, :6])
    with pytest.raises(TeachfitError, match="7 numbers"):
        Pose.from_array(states[0, :6])
    with pytest.raises(TeachfitError, match="unit norm"):
        Pose.from_array(np.r_[0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0])
    with pytest.raises(TeachfitError, match=r"\(4, 4\)"):
        Pose.from_matrix(np.eye(3))


def test_quat_angle_matches_scipy_magnitude_and_ignores_sign(rots):
    q = rotation_to_wxyz(rots)
    expected = (rots[0].inv() * rots).magnitude()
    assert np.allclose(quat_angle(q[0], q), expected, atol=1e-7)
    assert np.allclose(quat_angle(q[0], -q), expected, atol=1e-7)
    assert quat_angle(q[0], q[:1])[0] == pytest.approx(0.0, abs=1e-7)


def test_yaw_matches_scipy_zyx_euler(rots):
    q = rotation_to_wxyz(rots)
    expected = rots.as_euler("ZYX")[:, 0]
    assert np.allclose(rz_from_quat(q), expected, atol=1e-9)
    for qi, e in zip(q, expected, strict=True):
        assert yaw_of(qi) == pytest.approx(e, abs=1e-9)
    angles = np.linspace(-3.0, 3.0, 13)
    assert np.allclose([yaw_of(qz) for qz in quat_from_rz(angles)], angles, atol=1e-12)
    assert Pose.from_xyz_rz(0.0, 0.0, 0.0, 0.7).rz == pytest.approx(0.7)
