"""CSV export: what is exported reads back to the same demonstration."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from teachfit.core.errors import DatasetError
from teachfit.demonstrations.csv_import import ColumnMap, import_csv
from teachfit.demonstrations.dataset import read_demo, write_dataset
from teachfit.demonstrations.export import export_csv

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_csv_hdf5_csv_round_trip(tmp_path: Path) -> None:
    demo = import_csv(
        EXAMPLES / "robot_log.csv", ColumnMap.from_toml(EXAMPLES / "columns.toml"), task="peg2d"
    )
    h5 = write_dataset(tmp_path / "demos.h5", [demo])
    stored = read_demo(f"{h5}:0")
    out = export_csv(stored, tmp_path / "x.csv", columns=tmp_path / "x.toml")
    again = import_csv(out, ColumnMap.from_toml(tmp_path / "x.toml"), task="peg2d")
    for label in ("t", "pos", "quat", "wrench"):
        np.testing.assert_array_equal(getattr(again, label), getattr(stored, label), label)
    assert again.frame == stored.frame == "base"
    lines = out.read_text().splitlines()
    assert lines[0] == "time,x,y,z,qw,qx,qy,qz,fx,fy,fz,tx,ty,tz" and len(lines) == 61
    assert lines[1].split(",")[1] == "0.452106"  # shortest exact repr, not 17 noisy digits


def test_without_wrench_and_existing_files(tmp_path: Path) -> None:
    demo = import_csv(
        EXAMPLES / "robot_log.csv", ColumnMap.from_toml(EXAMPLES / "columns.toml"), task="peg2d"
    )
    bare = replace(demo, wrench=None)
    out = export_csv(bare, tmp_path / "x.csv", columns=tmp_path / "x.toml")
    assert out.read_text().splitlines()[0] == "time,x,y,z,qw,qx,qy,qz"
    assert "fx" not in (tmp_path / "x.toml").read_text()
    with pytest.raises(DatasetError, match="file exists") as info:
        export_csv(bare, out)
    assert info.value.path == str(out)
    export_csv(demo, out, overwrite=True)
    assert out.read_text().splitlines()[0].endswith("tz")
    assert not list(tmp_path.glob(".*.tmp*"))  # written atomically, nothing left behind
