"""Rendered clips end to end: synth -> track -> demonstration -> plan; occlusion, outliers,
bad input; ChArUco calibration of the synthetic rig. Small (640x480, ~11 frames), seeded.

Every test here works on clips rendered with MuJoCo, so each is skipped (with the reason) where
no OpenGL context exists; the capture code without rendering is tested in test_capture_*.py."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import imageio.v2 as imageio
import numpy as np
import pytest
from media_checks import read_png
from typer.testing import CliRunner

from teachfit.bench.capture import pose_errors
from teachfit.capture.calibrate import CharucoSpec, calibrate_folder
from teachfit.capture.geometry import invert, rotation_angle_deg
from teachfit.capture.markers import MarkerSet, read_markers, write_markers
from teachfit.capture.rig import read_rig
from teachfit.capture.sources import VideoSet
from teachfit.capture.synth import SynthConfig, write_synth_capture
from teachfit.capture.synth_calib import write_charuco_shots
from teachfit.capture.track import STATUS, track_frames
from teachfit.cli import app
from teachfit.core.errors import CaptureError
from teachfit.demonstrations.dataset import read_demo

CFG = SynthConfig(resolutions=((640, 480),) * 3, distance=0.35, stride=15, noise=1.0)


@pytest.fixture(scope="module")
def clip(tmp_path_factory, needs_gl) -> dict[str, Path]:
    return write_synth_capture(tmp_path_factory.mktemp("synth"), seed=3, cfg=CFG)


def _videos(clip, n=3):
    return [clip[f"video{i}"] for i in range(n)]


def _capture_markers(clip, markers: Path, out: Path, *extra: str) -> object:
    """``teachfit capture markers`` on the clip's three videos and rig."""
    videos = ["--video", *map(str, _videos(clip)), "--rig", str(clip["rig"])]
    args = ["capture", "markers", *videos, "--markers", str(markers), "--out", str(out)]
    return CliRunner().invoke(app, [*args, *extra])


def test_synth_writes_consistent_files(clip):
    rig, truth = read_rig(clip["rig"]), read_demo(clip["truth"])
    assert len(rig) == 3 and rig.cameras[0].width == 640
    assert truth.frame == "G" and truth.child_frame == "L" and truth.source == "synthetic"
    frames = [imageio.get_reader(v).count_frames() for v in _videos(clip)]
    assert frames == [truth.n_samples] * 3 and truth.n_samples >= 10
    np.testing.assert_allclose(np.diff(truth.t), CFG.stride / 30.0)


def test_three_cameras_track_accurately_and_plan(clip, tmp_path):
    out = tmp_path / "demo.h5"
    res = _capture_markers(
        clip,
        clip["markers"],
        out,
        "--truth",
        str(clip["truth"]),
        "--plot",
        str(tmp_path / "track.png"),
    )
    assert res.exit_code == 0, res.output
    read_png(tmp_path / "track.png", min_px=300)
    demo, truth = read_demo(out), read_demo(clip["truth"])
    assert demo.source == "captured" and demo.frame == "G" and demo.child_frame == "L"
    assert demo.n_samples == truth.n_samples  # every frame trustworthy in this clean clip
    err = 1e3 * np.linalg.norm(demo.pos - truth.pos, axis=1)
    assert np.median(err) < 0.5 and err.max() < 2.0
    printed = " ".join(res.output.split())
    assert f"error vs truth: median {np.median(err):.3f} mm" in printed
    args = ["plan", "--demo", f"{out}:0", "--max-checks", "2000", "--seed", "1"]
    res = CliRunner().invoke(app, args)  # a budget in checks: the outcome is the seed's alone
    assert res.exit_code == 0 and "success" in res.output, res.output


def test_one_camera_still_tracks(clip):
    rig, markers, truth = (
        read_rig(clip["rig"]),
        read_markers(clip["markers"]),
        read_demo(clip["truth"]),
    )
    sub = rig.subset([0])
    track = track_frames(VideoSet(_videos(clip, 1), sub), sub, markers)
    mm, deg = pose_errors(track, truth)
    assert track.valid.sum() >= 0.8 * track.n_frames
    assert np.median(mm) < 2.0 and np.median(deg) < 1.0


def _masked(frames, boxes_of):
    """Frames with grey boxes painted over (occluders): boxes_of(k, cam) -> list of boxes."""
    for k, (t, images) in enumerate(frames):
        out = []
        for cam, img in enumerate(images):
            img = img.copy()
            for x0, y0, x1, y1 in boxes_of(k, cam):
                img[y0:y1, x0:x1] = 128
            out.append(img)
        yield t, out


def _marker_box(rig, markers: MarkerSet, part2rig, cam, marker_id, pad=6):
    import cv2

    m = markers.by_id()[marker_id]
    c = rig.cameras[cam]
    X = m.corners_in_part @ part2rig[:3, :3].T + part2rig[:3, 3]
    X = X @ c.rig2cam[:3, :3].T + c.rig2cam[:3, 3]
    uv = cv2.projectPoints(X, np.zeros(3), np.zeros(3), c.K, c.dist)[0].reshape(4, 2)
    lo, hi = np.floor(uv.min(axis=0)).astype(int) - pad, np.ceil(uv.max(axis=0)).astype(int) + pad
    return (*np.maximum(lo, 0), *hi)


def test_occlusion_is_marked_not_invented(clip):
    from teachfit.tasks.parts import pose_from_xyz_rpy

    rig, markers, truth = (
        read_rig(clip["rig"]),
        read_markers(clip["markers"]),
        read_demo(clip["truth"]),
    )
    G2rig = pose_from_xyz_rpy(np.zeros(3), [0.0, 0.0, 15.0])  # as in write_synth_capture
    from scipy.spatial.transform import Rotation

    L2G = np.tile(np.eye(4), (truth.n_samples, 1, 1))
    L2G[:, :3, :3] = Rotation.from_quat(truth.quat[:, [1, 2, 3, 0]]).as_matrix()
    L2G[:, :3, 3] = truth.pos

    def boxes(k, cam):
        # frame 4: every L marker hidden in every camera; frames 2-3: hidden in cameras 1, 2
        if k == 4 or (k in (2, 3) and cam > 0):
            return [_marker_box(rig, markers, G2rig @ L2G[k], cam, i) for i in markers.ids_of("L")]
        return []

    track = track_frames(_masked(VideoSet(_videos(clip), rig), boxes), rig, markers)
    assert not track.valid[4] and STATUS[track.status[4]] == "no-moving"
    assert np.isnan(track.L2G[4]).all()
    assert track.valid[2] and track.valid[3]  # camera 0 alone carries the moving part
    mm, _ = pose_errors(track, truth)
    assert np.median(mm) < 0.5
    demo = track.to_demonstration("l-groove")
    assert demo.n_samples == truth.n_samples - 1 and demo.meta["dropped_frames"] == [4.0]


def test_wrong_marker_is_rejected_as_outlier(clip, tmp_path):
    rig, markers, truth = (
        read_rig(clip["rig"]),
        read_markers(clip["markers"]),
        read_demo(clip["truth"]),
    )
    shifted = []
    for m in markers.markers:
        if m.id == 10:  # pretend marker 10 was glued 15 mm off its documented place
            T = m.marker2part.copy()
            T[0, 3] += 0.015
            m = replace(m, marker2part=T)
        shifted.append(m)
    bad = replace(markers, markers=tuple(shifted))
    track = track_frames(VideoSet(_videos(clip), rig), rig, bad)
    mm, deg = pose_errors(track, truth)
    assert track.valid.mean() > 0.9 and np.median(mm) < 0.5 and np.median(deg) < 0.3


def test_bad_inputs_raise_clear_errors(clip, tmp_path):
    rig, markers = read_rig(clip["rig"]), read_markers(clip["markers"])
    junk = tmp_path / "junk.mp4"
    junk.write_text("not a video")
    with pytest.raises(CaptureError, match="junk.mp4.*cannot be opened"):
        VideoSet([junk, *_videos(clip)[1:]], rig)
    with pytest.raises(CaptureError, match="no such file"):
        VideoSet([tmp_path / "missing.mp4", *_videos(clip)[1:]], rig)
    with pytest.raises(CaptureError, match="2 video"):
        VideoSet(_videos(clip, 2), rig)
    copy = tmp_path / "copy.mp4"
    copy.write_bytes(Path(_videos(clip)[0]).read_bytes())
    with pytest.raises(CaptureError, match="same file"):
        VideoSet([_videos(clip)[0], copy, _videos(clip)[2]], rig)
    short = tmp_path / "short.mp4"
    reader = imageio.get_reader(_videos(clip)[0])
    fps = reader.get_meta_data()["fps"]
    with imageio.get_writer(short, fps=fps, codec="libx264", macro_block_size=1) as w:
        for k, img in enumerate(reader):
            if k < 5:
                w.append_data(img)
    with pytest.raises(CaptureError, match="frame counts differ"):
        VideoSet([short, *_videos(clip)[1:]], rig)
    slow = tmp_path / "slow.mp4"
    with imageio.get_writer(slow, fps=fps / 2, codec="libx264", macro_block_size=1) as w:
        for img in imageio.get_reader(_videos(clip)[0]):
            w.append_data(img)
    with pytest.raises(CaptureError, match="frame rates differ"):
        VideoSet([slow, *_videos(clip)[1:]], rig)
    # a marker file for another dictionary: its markers are never seen
    other = replace(markers, dictionary="DICT_5X5_50")
    with pytest.raises(CaptureError, match="no marker of part 'G'.*DICT_5X5_50"):
        track_frames(VideoSet(_videos(clip), rig), rig, other)
    path = write_markers(other, tmp_path / "m.toml")
    res = _capture_markers(clip, path, tmp_path / "x.h5")
    assert res.exit_code == 2 and "no marker of part" in res.output


def test_charuco_calibration_recovers_the_rig(tmp_path, needs_gl):
    spec = CharucoSpec()
    cfg = SynthConfig(resolutions=((640, 480),) * 2)
    truth = write_charuco_shots(tmp_path / "calib", spec, cfg, shots=12, seed=0)
    rig, report = calibrate_folder(tmp_path / "calib", spec)
    assert max(report.intrinsic_rms.values()) < 0.3
    for est, ref in zip(rig.cameras, truth.cameras, strict=True):
        np.testing.assert_allclose(est.K[[0, 1], [0, 1]], ref.K[[0, 1], [0, 1]], rtol=0.015)
    rel = invert(truth.cameras[0].cam2rig) @ truth.cameras[1].cam2rig
    E = invert(rel) @ rig.cameras[1].cam2rig
    assert 1e3 * np.linalg.norm(E[:3, 3]) < 10.0 and rotation_angle_deg(E[:3, :3]) < 0.5
    with pytest.raises(CaptureError, match="holds no camera"):
        calibrate_folder(tmp_path, spec)
