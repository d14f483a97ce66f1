"""Rig and marker files: round trips and clear errors on bad input."""

from __future__ import annotations

import numpy as np
import pytest

from teachfit.capture.geometry import checked_transform
from teachfit.capture.markers import (
    Marker,
    MarkerSet,
    marker_image,
    read_markers,
    write_markers,
)
from teachfit.capture.rig import Camera, Rig, read_rig, write_rig
from teachfit.core.errors import CaptureError
from teachfit.tasks.parts import pose_from_xyz_rpy


def _rig() -> Rig:
    K = np.array([[900.0, 0, 319.5], [0, 905.0, 239.5], [0, 0, 1]])
    T = pose_from_xyz_rpy(np.array([0.1, -0.2, 0.5]), [10, 20, 30])
    return Rig(
        (
            Camera("a", 640, 480, K, np.zeros(5), np.eye(4)),
            Camera("b", 640, 480, K, np.array([0.1, -0.02, 0.001, 0.0, 0.003]), T),
        )
    )


def test_rig_round_trip(tmp_path):
    rig = _rig()
    back = read_rig(write_rig(rig, tmp_path / "rig.toml"))
    assert [c.name for c in back.cameras] == ["a", "b"]
    for c, d in zip(rig.cameras, back.cameras, strict=True):
        np.testing.assert_array_equal(c.K, d.K)
        np.testing.assert_array_equal(c.dist, d.dist)
        np.testing.assert_array_equal(c.cam2rig, d.cam2rig)
    np.testing.assert_allclose(
        back.cameras[1].rig2cam @ back.cameras[1].cam2rig, np.eye(4), atol=1e-12
    )


def test_rig_rejects_non_rotation(tmp_path):
    path = write_rig(_rig(), tmp_path / "rig.toml")
    text = path.read_text().replace(
        "cam2rig = [\n  [1.0, 0.0, 0.0, 0.0]", "cam2rig = [\n  [1.1, 0.0, 0.0, 0.0]", 1
    )
    path.write_text(text)
    with pytest.raises(CaptureError, match=r"rig\.toml.*camera 'a' cam2rig.*not a rotation"):
        read_rig(path)
    reflection = np.diag([1.0, 1.0, -1.0, 1.0])
    with pytest.raises(CaptureError, match="det = -1"):
        checked_transform(reflection, "x")


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda s: s.replace('format = "teachfit-rig"', 'format = "other"'), "expected format"),
        (lambda s: s.replace("width = 640\n", "", 1), "lacks width"),
        (lambda s: s.replace('name = "b"', 'name = "a"'), "unique"),
        (lambda s: s.replace("dist = [0.0, 0.0, 0.0, 0.0, 0.0]", "dist = [0.0, 0.0]"), "dist"),
        (lambda s: s + "[[[", "invalid TOML"),
    ],
)
def test_rig_errors(tmp_path, edit, message):
    path = write_rig(_rig(), tmp_path / "rig.toml")
    path.write_text(edit(path.read_text()))
    with pytest.raises(CaptureError, match=message):
        read_rig(path)


def test_rig_missing_file(tmp_path):
    with pytest.raises(CaptureError, match="cannot read"):
        read_rig(tmp_path / "nope.toml")


def _markers() -> MarkerSet:
    return MarkerSet(
        "DICT_4X4_50",
        (
            Marker(0, "L", 0.02, pose_from_xyz_rpy(np.array([0, 0, 0.05]), [0, 0, 0])),
            Marker(7, "G", 0.03, pose_from_xyz_rpy(np.array([0.1, 0, 0]), [0, 90, 0])),
        ),
    )


def test_markers_round_trip(tmp_path):
    ms = _markers()
    back = read_markers(write_markers(ms, tmp_path / "m.toml"))
    assert back.dictionary == "DICT_4X4_50" and back.ids_of("L") == [0] and back.ids_of("G") == [7]
    np.testing.assert_array_equal(back.by_id()[7].marker2part, ms.by_id()[7].marker2part)
    # corners in the part frame: a marker turned 90 deg about y lies in the y-z plane
    assert np.allclose(back.by_id()[7].corners_in_part[:, 0], 0.1)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"dictionary": "DICT_9X9"}, "unknown ArUco dictionary"),
        (
            {"markers": (Marker(1, "L", 0.02, np.eye(4)), Marker(1, "G", 0.02, np.eye(4)))},
            "duplicate",
        ),
        (
            {"markers": (Marker(60, "L", 0.02, np.eye(4)), Marker(1, "G", 0.02, np.eye(4)))},
            "ids 0..49",
        ),
        ({"markers": (Marker(1, "L", 0.02, np.eye(4)),)}, "part 'G' has no marker"),
        (
            {"markers": (Marker(1, "X", 0.02, np.eye(4)), Marker(2, "G", 0.02, np.eye(4)))},
            "part 'X'",
        ),
    ],
)
def test_marker_set_errors(kwargs, message):
    args = {"dictionary": "DICT_4X4_50", "markers": _markers().markers} | kwargs
    with pytest.raises(CaptureError, match=message):
        MarkerSet(**args)


def test_marker_validation_and_image():
    with pytest.raises(CaptureError, match="size"):
        Marker(0, "L", -0.01, np.eye(4))
    with pytest.raises(CaptureError, match="not a rotation"):
        Marker(0, "L", 0.01, np.diag([2.0, 1.0, 1.0, 1.0]))
    img = marker_image("DICT_4X4_50", 3, 60, margin=0.25)
    assert img.shape == (90, 90) and img.dtype == np.uint8
    assert (img[:15] == 255).all() and img[15:75, 15:75].min() == 0
