"""Damaged bags (bytes flipped or cut short, seeded): each is read or refused with a
DatasetError naming the bag, never another exception."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from panda_logs import write_bag

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.rosbag_import import read_bag


@pytest.mark.parametrize("storage", ["ros1", "sqlite3", "mcap"])
def test_damaged_bags_are_refused_cleanly(tmp_path: Path, storage: str) -> None:
    good = tmp_path / ("good.bag" if storage == "ros1" else "good")
    write_bag(good, storage=storage)
    part = good if storage == "ros1" else next(p for p in good.iterdir() if p.suffix != ".yaml")
    data = part.read_bytes()
    rng = np.random.default_rng(0)
    refused = 0
    for k in range(12):
        damaged = bytearray(data)
        for i in rng.integers(0, len(data), rng.integers(1, 20)):
            damaged[i] = int(rng.integers(0, 256))
        if k % 3 == 0:
            damaged = damaged[: int(rng.integers(0, len(data)))]
        bag = tmp_path / f"damaged{k}{good.suffix}"
        if storage != "ros1":
            shutil.copytree(good, bag)
        (bag if storage == "ros1" else bag / part.name).write_bytes(bytes(damaged))
        try:
            read_bag(bag, "/tcp_pose", "/ft_sensor")
        except DatasetError as exc:
            assert str(exc).startswith(f"file {bag}: ") and "\n" not in str(exc)
            refused += 1
    assert refused >= 6
