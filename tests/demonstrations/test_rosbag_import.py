"""ROS 1 and ROS 2 (sqlite3 and MCAP) bags, written here with rosbags' own writers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from panda_logs import TF, TRANSFORM, write_bag

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.importing import ImportOptions, build_demos
from teachfit.demonstrations.rosbag_import import is_bag, read_bag


@pytest.mark.parametrize("storage", ["ros1", "sqlite3", "mcap"])
def test_pose_and_wrench_topics(tmp_path: Path, storage: str) -> None:
    path = tmp_path / ("run.bag" if storage == "ros1" else "run")
    truth = write_bag(path, storage)
    assert is_bag(path)
    log = read_bag(path, "/tcp_pose", "/ft_sensor")
    assert log.meta["source_format"] == ("ros1" if storage == "ros1" else "ros2")
    assert log.frame == "panda_link0" and log.meta["time_offset_s"] == pytest.approx(1718023402.0)
    # the first pose stamp lies before the first wrench (3 ms later): dropped, with a note
    assert log.n_samples == truth["t"].size - 1 and "dropped 1 /tcp_pose samples" in log.notes[0]
    np.testing.assert_allclose(log.t, truth["t"][1:] - truth["t"][1], atol=1e-9)
    np.testing.assert_allclose(log.pos, truth["pos"][1:], atol=1e-12)
    np.testing.assert_allclose(log.quat, truth["quat"][1:], atol=1e-12)
    # wrench interpolated from the 50 Hz stream back onto the pose stamps
    w_t = np.arange(0.003, truth["t"][-1] + 0.1, 0.02)
    resampled = [np.interp(w_t, truth["t"], truth["wrench"][:, k]) for k in range(6)]
    expect = np.column_stack([np.interp(truth["t"][1:], w_t, r) for r in resampled])
    np.testing.assert_allclose(log.wrench, expect, atol=1e-9)
    (demo,) = build_demos(log, task="peg2d", name="run", options=ImportOptions()).demos
    assert demo.rate_hz == pytest.approx(20.0) and demo.meta["wrench_topic"] == "/ft_sensor"


def test_mcap_file_and_tf_topic(tmp_path: Path) -> None:
    truth = write_bag(tmp_path / "run", "mcap", pose_kind=TF)
    (mcap,) = (tmp_path / "run").glob("*.mcap")
    with pytest.raises(DatasetError, match="several child frames .* --child-frame"):
        read_bag(mcap, "/tcp_pose")
    log = read_bag(mcap, "/tcp_pose", child_frame="panda_hand_tcp")
    assert log.wrench is None and log.n_samples == truth["t"].size
    np.testing.assert_allclose(log.pos, truth["pos"], atol=1e-12)


def test_transform_stamped_topic(tmp_path: Path) -> None:
    truth = write_bag(tmp_path / "run.bag", pose_kind=TRANSFORM)
    log = read_bag(tmp_path / "run.bag", "/tcp_pose", "/ft_sensor")
    assert log.frame == "panda_link0" and log.n_samples == truth["t"].size - 1
    np.testing.assert_allclose(log.quat, truth["quat"][1:], atol=1e-12)


def test_wrench_in_the_sensor_frame_is_rotated(tmp_path: Path) -> None:
    truth = write_bag(tmp_path / "run.bag", wrench_frame="ft_sensor")
    log = read_bag(tmp_path / "run.bag", "/tcp_pose", "/ft_sensor")
    assert any("rotated it into 'panda_link0'" in n for n in log.notes)
    # tool pointing down: the sensor's +z force is -z in the base frame
    in_contact = truth["wrench"][1:, 2] > 5.0
    assert np.all(log.wrench[in_contact, 2] < 0)


def test_wrong_sign_and_bad_topics(tmp_path: Path) -> None:
    path = tmp_path / "run.bag"
    write_bag(path, wrench_sign=-1.0)
    log = read_bag(path, "/tcp_pose", "/ft_sensor")
    with pytest.raises(DatasetError) as info:
        build_demos(log, task="peg2d", name="run", options=ImportOptions())
    message = str(info.value)
    assert message.startswith(f"file {path}: implausible wrench_sign")
    assert "flip wrench_sign, pass --wrench-sign -1" in message
    flipped = read_bag(path, "/tcp_pose", "/ft_sensor", wrench_sign=-1)
    assert build_demos(flipped, task="peg2d", name="run", options=ImportOptions()).demos
    with pytest.raises(DatasetError, match=r"no topic '/pose' in the bag \(topics: /tcp_pose"):
        read_bag(path, "/pose")
    with pytest.raises(DatasetError, match="carries geometry_msgs/msg/WrenchStamped, expected"):
        read_bag(path, "/ft_sensor")
    (tmp_path / "junk.bag").write_bytes(b"not a bag")
    with pytest.raises(DatasetError, match="cannot read as a ROS bag") as info:
        read_bag(tmp_path / "junk.bag", "/tcp_pose")
    assert info.value.path == str(tmp_path / "junk.bag")
