"""Single-marker poses, edge refinement, multi-camera fusion and the temporal filter, on
synthetic projections and images (no rendering)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from teachfit.capture.detect import (
    Detection,
    DetectorConfig,
    detect_markers,
    make_detector,
    square_poses,
)
from teachfit.capture.fuse import FusionConfig, fuse_part, relative_pose
from teachfit.capture.geometry import invert, rotation_angle_deg
from teachfit.capture.markers import Marker, marker_image
from teachfit.capture.rig import Camera, Rig
from teachfit.capture.scene import camera_K, look_at
from teachfit.capture.temporal import FilterConfig, PoseFilter
from teachfit.tasks.parts import pose_from_xyz_rpy

K = camera_K(1280, 720, 40.0)


def _rig(n: int = 3) -> Rig:
    cams = []
    for i in range(n):
        az = np.radians(120 * i + 10)
        eye = 0.6 * np.array([0.7 * np.cos(az), 0.7 * np.sin(az), 0.7])
        cams.append(Camera(f"c{i}", 1280, 720, K, np.zeros(5), look_at(eye, np.zeros(3))))
    return Rig(tuple(cams))


def _cube_markers() -> dict[int, Marker]:
    faces = [
        ([0, 0, 0.015], [0, 0, 0]),
        ([0.015, 0, 0], [90, 0, 90]),
        ([-0.015, 0, 0], [90, 0, -90]),
        ([0, -0.015, 0], [90, 0, 0]),
    ]
    return {
        i: Marker(i, "L", 0.022, pose_from_xyz_rpy(np.array(p), r))
        for i, (p, r) in enumerate(faces)
    }


def _observe(rig, markers, part2rig, rng, noise=0.05):
    dets = []
    for c, cam in enumerate(rig.cameras):
        for m in markers.values():
            X = m.corners_in_part @ part2rig[:3, :3].T + part2rig[:3, 3]
            normal = part2rig[:3, :3] @ m.marker2part[:3, 2]
            if np.dot(normal, cam.cam2rig[:3, 3] - X.mean(axis=0)) <= 0:
                continue  # facing away
            Xc = X @ cam.rig2cam[:3, :3].T + cam.rig2cam[:3, 3]
            uv, _ = cv2.projectPoints(Xc, np.zeros(3), np.zeros(3), cam.K, cam.dist)
            dets.append(Detection(c, m.id, uv.reshape(4, 2) + rng.normal(0, noise, (4, 2))))
    return dets


def _err(A, B):
    E = invert(A) @ B
    return 1e3 * np.linalg.norm(A[:3, 3] - B[:3, 3]), float(rotation_angle_deg(E[:3, :3]))


def test_square_poses_returns_both_ippe_solutions():
    m2c = pose_from_xyz_rpy(np.array([0.02, -0.01, 0.5]), [25, -15, 10])
    X = np.array([[-0.011, 0.011, 0], [0.011, 0.011, 0], [0.011, -0.011, 0], [-0.011, -0.011, 0]])
    uv, _ = cv2.projectPoints(X @ m2c[:3, :3].T + m2c[:3, 3], np.zeros(3), np.zeros(3), K, None)
    poses = square_poses(uv.reshape(4, 2), 0.022, K, np.zeros(5))
    assert len(poses) == 2 and poses[0][1] <= poses[1][1]
    mm, deg = _err(m2c, poses[0][0])
    assert mm < 1e-3 and deg < 1e-3
    assert _err(m2c, poses[1][0])[1] > 5.0  # the mirrored solution is genuinely different


def test_fusion_over_cameras_is_accurate_and_rejects_outliers():
    rng = np.random.default_rng(0)
    rig, markers = _rig(), _cube_markers()
    truth = pose_from_xyz_rpy(np.array([0.01, 0.02, 0.03]), [10, -20, 40])
    dets = _observe(rig, markers, truth, rng)
    pose = fuse_part(dets, rig, markers)
    mm, deg = _err(truth, pose.part2rig)
    assert mm < 0.1 and deg < 0.1 and len(pose.cameras) == 3 and not pose.rejected
    # a corrupted marker (wrong corners by 6 px) is rejected and the pose stays accurate
    bad = [
        Detection(d.camera, d.marker_id, d.corners + (6.0 if d.marker_id == 0 else 0.0))
        for d in dets
    ]
    pose2 = fuse_part(bad, rig, markers)
    assert 0 in pose2.rejected and _err(truth, pose2.part2rig)[0] < 0.2
    # the predicted error is of the right order: 1-sigma within 3x of the actual error
    std_mm = 1e3 * np.sqrt(np.trace(pose.cov[3:, 3:]))
    assert 0.005 < std_mm < 0.5


def test_single_camera_single_marker_and_prior():
    rng = np.random.default_rng(1)
    rig, markers = _rig(1), {0: _cube_markers()[0]}
    truth = pose_from_xyz_rpy(np.array([0.0, 0.0, 0.0]), [0, 0, 30])
    dets = _observe(rig, markers, truth, rng, noise=0.3)
    assert len(dets) == 1
    pose = fuse_part(dets, rig, markers, prior=truth)
    assert _err(truth, pose.part2rig)[1] < 3.0
    assert fuse_part([], rig, markers) is None


def test_relative_pose_and_its_covariance():
    rng = np.random.default_rng(2)
    rig, markers = _rig(), _cube_markers()
    G = pose_from_xyz_rpy(np.array([-0.05, 0.0, 0.0]), [0, 0, 15])
    L = pose_from_xyz_rpy(np.array([0.05, 0.02, 0.04]), [5, -25, 0])
    samples = []
    for _ in range(40):
        g = fuse_part(_observe(rig, markers, G, rng, 0.2), rig, markers)
        lp = fuse_part(_observe(rig, markers, L, rng, 0.2), rig, markers)
        L2G, cov = relative_pose(g, lp)
        samples.append(L2G[:3, 3])
    np.testing.assert_allclose(np.mean(samples, axis=0), (invert(G) @ L)[:3, 3], atol=2e-4)
    predicted = np.sqrt(np.trace(cov[3:, 3:]))
    actual = np.sqrt(np.sum(np.var(samples, axis=0)))
    assert 0.4 < actual / predicted < 2.5


def _warped_marker(corners: np.ndarray, size=(480, 360), blur=1.0) -> np.ndarray:
    """A marker drawn with 8x supersampling at sub-pixel ``corners`` (IPPE order), blurred."""
    img = marker_image("DICT_4X4_50", 5, 120, margin=0.25)
    src = np.array([[30, 30], [150, 30], [150, 150], [30, 150]], dtype=np.float32) - 0.5
    s = 8
    H = cv2.getPerspectiveTransform(src, ((corners + 0.5) * s - 0.5).astype(np.float32))
    big = cv2.warpPerspective(
        img, H, (size[0] * s, size[1] * s), flags=cv2.INTER_LINEAR, borderValue=128
    )
    small = cv2.resize(big, size, interpolation=cv2.INTER_AREA)
    return cv2.GaussianBlur(small, (0, 0), blur)


def test_edge_refinement_beats_corner_refinement():
    rng = np.random.default_rng(3)
    gains = []
    for _ in range(5):
        c = np.array([[200, 120], [262, 126], [258, 190], [196, 184]], float) + rng.uniform(
            -2, 2, (4, 2)
        )
        img = _warped_marker(c)
        det = make_detector("DICT_4X4_50", DetectorConfig(fast=False))
        raw = detect_markers(det, img, 0, {5})
        refined = detect_markers(det, img, 0, {5}, (K, np.zeros(5)))
        assert len(raw) == len(refined) == 1
        gains.append((np.abs(raw[0].corners - c).mean(), np.abs(refined[0].corners - c).mean()))
    raw_err, ref_err = np.mean(gains, axis=0)
    assert ref_err < 0.06 and ref_err < 0.5 * raw_err


def _pose(x_mm: float, yaw_deg: float = 0.0) -> np.ndarray:
    return pose_from_xyz_rpy(np.array([1e-3 * x_mm, 0.0, 0.0]), [0, 0, yaw_deg])


def test_filter_tracks_constant_velocity_and_gates_jumps():
    f = PoseFilter(
        FilterConfig(
            alpha=0.5,
            beta=0.2,
            accel=None,
            gate_mm=5.0,
            gate_deg=5.0,
            gate_accel=0.0,
            gate_ang_accel=0.0,
            reacquire=3,
        )
    )
    out = [f.update(k / 30, _pose(2.0 * k, 0.5 * k)) for k in range(60)]
    assert abs(1e3 * out[-1][0, 3] - 118.0) < 0.01  # no lag on constant velocity
    # a single 20 mm jump is rejected (None, not invented), tracking continues after it
    assert f.update(60 / 30, _pose(140.0)) is None
    assert f.update(61 / 30, _pose(122.0, 30.5)) is not None
    # a lasting jump is reacquired after `reacquire` rejections
    results = [f.update((62 + k) / 30, _pose(300.0)) for k in range(3)]
    assert results[0] is None and results[1] is None and results[2] is not None
    assert f.update(70 / 30, None) is None
    with pytest.raises(Exception, match="alpha"):
        FilterConfig(alpha=0.0)


def test_fusion_config_validation():
    with pytest.raises(Exception, match="outlier_px"):
        FusionConfig(outlier_px=0.0)
