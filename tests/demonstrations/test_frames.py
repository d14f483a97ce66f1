"""Frame transforms and quaternion orders."""

from __future__ import annotations

import numpy as np
import pytest

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.frames import FrameTransform, to_wxyz


def test_parse_forms() -> None:
    assert FrameTransform.parse("first-pose").first_pose
    cli = FrameTransform.parse("world:1,2,3,0,0,0,1")
    assert (cli.to, cli.pos, cli.quat) == ("world", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0))
    table = FrameTransform.parse({"to": "task", "pos": [0, 0, 1]})
    assert table.to == "task" and table.quat == (1.0, 0.0, 0.0, 0.0)
    bad = ["world:1,2,3", "second-pose", {"pos": [0, 0, 0]}, {"to": "w", "rot": [1, 0, 0, 0]}, 3]
    for value in bad:
        with pytest.raises(DatasetError) as info:
            FrameTransform.parse(value)
        assert info.value.column == "transform", value
    with pytest.raises(DatasetError, match="unit quaternion") as info:
        FrameTransform(quat=(1.0, 1.0, 0.0, 0.0))
    assert info.value.column == "quat"
    with pytest.raises(DatasetError, match="3 finite numbers"):
        FrameTransform(pos=(0.0, float("nan"), 0.0))


def test_fixed_transform_maps_points_orientations_and_wrenches() -> None:
    # log frame rotated +90 deg about z in the target, origin at (1, 0, 0)
    c = np.sqrt(0.5)
    transform = FrameTransform(to="world", pos=(1.0, 0.0, 0.0), quat=(c, 0.0, 0.0, c))
    pos = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.5]])
    quat = np.array([[1.0, 0.0, 0.0, 0.0], [c, 0.0, 0.0, c]])
    wrench = np.array([[1.0, 0.0, 5.0, 0.0, 1.0, 0.0]] * 2)
    new_pos, new_quat, new_wrench, pose = transform.apply(pos, quat, wrench)
    np.testing.assert_allclose(new_pos, [[1.0, 1.0, 0.0], [-1.0, 0.0, 0.5]], atol=1e-12)
    np.testing.assert_allclose(new_quat, [[c, 0.0, 0.0, c], [0.0, 0.0, 0.0, 1.0]], atol=1e-12)
    np.testing.assert_allclose(new_wrench, [[0.0, 1.0, 5.0, -1.0, 0.0, 0.0]] * 2, atol=1e-12)
    assert pose == [1.0, 0.0, 0.0, c, 0.0, 0.0, c] and transform.target("base") == "world"


def test_first_pose_and_orders() -> None:
    pos = np.array([[0.4, -0.1, 0.3], [0.41, -0.1, 0.3]])
    quat = np.tile([0.0, 1.0, 0.0, 0.0], (2, 1))
    anchored = FrameTransform(first_pose=True)
    new_pos, new_quat, wrench, pose = anchored.apply(pos, quat, None)
    np.testing.assert_allclose(new_pos, [[0.0, 0.0, 0.0], [0.01, 0.0, 0.0]], atol=1e-15)
    assert (
        new_quat is quat
        and wrench is None
        and anchored.target("panda_link0") == ("panda_link0_start")
    )
    assert pose == [-0.4, 0.1, -0.3, 1.0, 0.0, 0.0, 0.0]
    np.testing.assert_array_equal(
        to_wxyz(np.array([[1.0, 2.0, 3.0, 4.0]]), "x,y,z,w"), [[4.0, 1.0, 2.0, 3.0]]
    )
    with pytest.raises(DatasetError, match="quat_order"):
        to_wxyz(quat, "z,y,x,w")
