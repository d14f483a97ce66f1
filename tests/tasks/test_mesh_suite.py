"""The parts suite: published nominal sizes, the simulated clearance, task files that load."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh import suite
from teachfit.tasks.registry import load_task


def _hole_extent(part: suite.Part) -> np.ndarray:
    """The hole's x-y extent (mm) 1 mm below the plate's top, from the plate mesh's section."""
    plate = suite.plate(part)
    z = suite.PLATE_THICKNESS - 1.0
    sec = plate.section(plane_origin=[0.0, 0.0, z], plane_normal=[0.0, 0.0, 1.0])
    loops = [v for v in sec.discrete if np.ptp(v[:, 0]) < part.width + 1.0]  # not the outline
    assert len(loops) == 1
    return np.ptp(loops[0][:, :2], axis=0)


@pytest.mark.parametrize("name", list(suite.PARTS))
def test_each_part_is_a_watertight_pair_at_its_nominal_size_and_clearance(name: str) -> None:
    part = suite.PARTS[name]
    peg, plate = suite.meshes(name)
    assert peg.is_watertight and plate.is_watertight
    assert peg.volume > 0 and plate.volume > 0
    hole = _hole_extent(part)
    nominal = np.array(part.hole_size)
    assert hole == pytest.approx(nominal, abs=1e-3)  # the published nominal (H: +0)
    assert peg.extents[:2] == pytest.approx(nominal - suite.SIM_CLEARANCE, abs=1e-3)
    depth = suite.PLATE_THICKNESS if part.through else suite.BLIND_DEPTH
    removed = (part.width + 40.0) ** 2 * suite.PLATE_THICKNESS - plate.volume
    area = math.pi * part.width**2 / 4 if part.round else part.width * part.height
    assert removed == pytest.approx(area * depth, rel=0.03)  # the chamfer adds < 3 %


def test_iso_286_h7_g6_clearances_of_the_nominal_ranges() -> None:
    assert suite.iso_clearance(8.0) == pytest.approx((0.005, 0.029))
    assert suite.iso_clearance(12.0) == pytest.approx((0.006, 0.035))
    assert suite.iso_clearance(16.0) == pytest.approx((0.006, 0.035))
    with pytest.raises(TaskError, match="no ISO 286"):
        suite.iso_clearance(25.0)


def test_write_suite_refuses_an_unknown_part_or_a_bad_clearance_before_writing(
    tmp_path: Path,
) -> None:
    with pytest.raises(TaskError, match="unknown suite part"):
        suite.write_suite(tmp_path / "out", ["round8-sharp-through", "hexagon"])
    for bad in (0.0, -0.1, 2.0):
        with pytest.raises(TaskError, match="give a diametral clearance in"):
            suite.write_suite(tmp_path / "out", clearance=bad)
    assert not (tmp_path / "out").exists()


def test_a_part_at_an_iso_fit_s_clearance() -> None:
    part = suite.PARTS["round8-sharp-through"].at_clearance(0.029)
    assert suite.peg(part).extents[:2] == pytest.approx([7.971, 7.971], abs=1e-3)
    assert "simulated 0.029 mm" in part.describe()


@pytest.mark.parametrize("name", ["round12-chamfer-blind", "rect12x8-sharp-through"])
def test_the_task_files_load_with_the_simulated_clearance(tmp_path: Path, name: str) -> None:
    (path,) = suite.write_suite(tmp_path, [name])
    task = load_task(str(path))
    assert Path(task.name).stem == name
    assert task.cell.fit.clearance == pytest.approx(suite.SIM_CLEARANCE / 2 * 1e-3, rel=0.02)
