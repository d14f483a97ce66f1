"""Where a mesh task's part stops (the table, a hole's bottom, a shoulder), the success depth
it defaults to, the openings on any face of the fixed part, and the fit's yaw period."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import manifold3d
import numpy as np
import pytest
import shapely
import trimesh
from shapely import affinity

from teachfit.core.errors import TaskError
from teachfit.robot.cell_checks import run_cell_checks
from teachfit.tasks.mesh.authoring import describe, new_task_file
from teachfit.tasks.mesh.cell import build_cell
from teachfit.tasks.mesh.examples import _stl, chamfered_bar
from teachfit.tasks.mesh.loading import from_manifold, to_manifold
from teachfit.tasks.mesh.sections import rz_period_of
from teachfit.tasks.mesh.spec import MeshTaskSpec, spec_to_toml
from teachfit.tasks.mesh.task import load_mesh_task

Box = tuple[float, float, float]


def _box(lo: Box, hi: Box) -> manifold3d.Manifold:
    return manifold3d.Manifold.cube([h - low for low, h in zip(lo, hi, strict=True)]).translate(
        list(lo)
    )


def _write(folder: Path, name: str, mesh: trimesh.Trimesh | manifold3d.Manifold) -> Path:
    path = folder / name
    m = from_manifold(mesh) if isinstance(mesh, manifold3d.Manifold) else mesh
    path.write_bytes(_stl(m))
    return path


def _peg(folder: Path, hx: float = 5.0, hy: float = 5.0) -> Path:
    """A 30 mm bar of 2 hx x 2 hy mm, flat tip (mm)."""
    return _write(folder, "peg.stl", chamfered_bar(hx, hy, 30.0, 1e-4))


def _plate(folder: Path, holes: list[tuple[float, float]]) -> Path:
    """A 60 x 40 x 9 mm plate with square through holes (centre x, side) on y = 0 (mm)."""
    plate = _box((-30.0, -20.0, 0.0), (30.0, 20.0, 9.0))
    for x, side in holes:
        plate = plate - _box((x - side / 2, -side / 2, -1.0), (x + side / 2, side / 2, 10.0))
    return _write(folder, "plate.stl", plate)


def test_a_peg_in_a_through_hole_plate_stops_on_the_table(tmp_path: Path) -> None:
    spec = MeshTaskSpec(
        path=tmp_path / "t.toml",
        held_mesh=_peg(tmp_path),
        fixed_mesh=_plate(tmp_path, [(0.0, 10.2)]),
        units="mm",
    )
    spec.path.write_text(spec_to_toml(spec))  # no success_depth, no rz_period_deg
    task = load_mesh_task(spec.path)
    cell = task.cell
    assert cell.fit.hole_depth == pytest.approx(0.009, abs=1e-6)
    assert cell.fit.stop_depth == pytest.approx(0.009, abs=1e-6)
    assert task.success_depth == pytest.approx(0.6 * 0.009, abs=1e-6)  # from the hole's depth
    assert task.rz_period == pytest.approx(np.pi / 2)  # inferred: a square
    rows = dict(describe(task))
    assert "on the table" in rows["aligned part stops at"]
    assert "default: 60 % of the 9.000 mm stop depth" in rows["success depth"]
    aligned = run_cell_checks(task)[0]
    assert aligned.passed, aligned  # not 28 mm through the table: 9 mm and no deeper
    assert aligned.depth == pytest.approx(0.009, abs=2e-4)
    assert "<= 9.00 mm" in aligned.expected


def test_a_shoulder_stops_the_part_above_a_deep_hole(tmp_path: Path) -> None:
    tip = to_manifold(chamfered_bar(5.0, 5.0, 5.0, 1e-4))
    held = from_manifold(tip + _box((-8.0, -8.0, 5.0), (8.0, 8.0, 20.0)))
    block = _box((-30.0, -30.0, 0.0), (30.0, 30.0, 20.0)) - _box(
        (-5.1, -5.1, 8.0), (5.1, 5.1, 21.0)
    )
    spec = MeshTaskSpec(
        path=tmp_path / "t.toml",
        held_mesh=_write(tmp_path, "held.stl", held),
        fixed_mesh=_write(tmp_path, "block.stl", block),
        units="mm",
    )
    cell = build_cell(spec)
    assert cell.fit.hole_depth == pytest.approx(0.012, abs=1e-6)
    assert 0.005 <= cell.fit.stop_depth <= 0.0052  # the head meets the top face (one step)
    assert cell.success_depth == pytest.approx(0.6 * cell.fit.stop_depth)
    with pytest.raises(TaskError, match="deeper than the place where the aligned part stops"):
        build_cell(dataclasses.replace(spec, success_depth=8.0))


def test_a_hole_in_a_side_face_is_found_along_its_axis(tmp_path: Path) -> None:
    block = _box((-20.0, -15.0, 0.0), (20.0, 15.0, 20.0))
    # 6.2 mm along y, 10.2 mm along z: the 10 x 6 peg fits it only turned by 90 degrees
    block = block - _box((10.0, -3.1, 4.9), (21.0, 3.1, 15.1))
    fixed = _write(tmp_path, "block.stl", block)
    new = new_task_file(tmp_path / "side.toml", _peg(tmp_path, 5.0, 3.0), fixed, "mm")
    spec = new.cell.spec
    assert len(new.openings) == 1 and new.chosen == 0
    assert spec.insertion_axis == (-1.0, 0.0, 0.0)
    assert spec.hole_pos == pytest.approx((20.0, 0.0, 10.0))
    assert new.cell.fit.hole_depth == pytest.approx(0.010, abs=1e-6)  # blind, 10 mm deep
    assert new.cell.fit.clearance == pytest.approx(1e-4, abs=1e-6)
    assert new.cell.rz_period_deg == pytest.approx(180.0)  # a rectangle
    task = load_mesh_task(new.path)  # the file written says the same
    assert task.cell.spec.insertion_axis == (-1.0, 0.0, 0.0)
    assert task.rz_period == pytest.approx(np.pi)


def test_two_holes_are_listed_and_chosen_by_number_or_position(tmp_path: Path) -> None:
    peg, plate = _peg(tmp_path), _plate(tmp_path, [(-12.0, 10.2), (12.0, 11.0)])
    best = new_task_file(tmp_path / "best.toml", peg, plate, "mm")
    assert [o.pos[0] for o in best.openings] == pytest.approx([-0.012, 0.012])
    assert best.chosen == 0 and best.cell.spec.hole_pos == (-12.0, 0.0, 9.0)  # tightest fit
    second = new_task_file(tmp_path / "second.toml", peg, plate, "mm", hole=2)
    assert second.chosen == 1 and second.cell.spec.hole_pos == (12.0, 0.0, 9.0)
    near = new_task_file(tmp_path / "near.toml", peg, plate, "mm", hole_at=(11.0, 1.0, 0.0))
    assert near.chosen == 1
    for bad in (0, 3):
        out = tmp_path / f"bad{bad}.toml"
        with pytest.raises(TaskError, match=rf"--hole {bad}: .* 2 opening\(s\); choose 1 to 2"):
            new_task_file(out, peg, plate, "mm", hole=bad)
        assert not out.exists()
    out = tmp_path / "both.toml"
    with pytest.raises(TaskError, match="--hole or --hole-at, not both"):
        new_task_file(out, peg, plate, "mm", hole=1, hole_at=(0.0, 0.0, 0.0))
    with pytest.raises(TaskError, match="drop --hole-pos"):
        new_task_file(out, peg, plate, "mm", hole_pos=(12.0, 0.0, 9.0), hole=1)
    assert not out.exists()


def test_a_bad_hole_number_is_one_line_and_exit_2(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from teachfit.cli import app

    peg, plate = _peg(tmp_path), _plate(tmp_path, [(-12.0, 10.2), (12.0, 11.0)])
    out = tmp_path / "t.toml"
    args = ["tasks", "new", str(out), "--held", str(peg), "--fixed", str(plate)]
    res = CliRunner().invoke(app, [*args, "--units", "mm", "--hole", "5"])
    assert res.exit_code == 2 and "--hole 5" in res.output and "choose 1 to 2" in res.output
    assert "Traceback" not in res.output and not out.exists()
    res = CliRunner().invoke(app, [*args, "--units", "mm"])
    assert res.exit_code == 0, res.output
    assert "1: entry (-12, 0, 9) mm" in res.output and "<- chosen" in res.output
    assert "yaw period 90 deg" in res.output


def _walls(hole: shapely.Polygon) -> shapely.Polygon:
    return shapely.box(-0.05, -0.05, 0.05, 0.05).difference(hole)


def _rect(hx: float, hy: float) -> shapely.Polygon:
    return shapely.box(-hx, -hy, hx, hy)


def _square(h: float) -> shapely.Polygon:
    return _rect(h, h)


TRIANGLE = shapely.Polygon([(-0.006, -0.004), (0.006, -0.004), (0.0, 0.008)])  # centroid: 0
SECTIONS = {  # hole, part (m) and the fit's yaw period (deg)
    "square": (_square(0.0051), _square(0.005), 90),
    "rectangle": (_rect(0.0061, 0.0031), _rect(0.006, 0.003), 180),
    "round": (shapely.Point(0, 0).buffer(0.007, 64), shapely.Point(0, 0).buffer(0.006, 64), 0),
    "isosceles": (TRIANGLE, affinity.scale(TRIANGLE, 0.9, 0.9, origin=(0, 0)), 360),
}  # fmt: skip


@pytest.mark.parametrize(("hole", "part", "deg"), SECTIONS.values(), ids=SECTIONS.keys())
def test_yaw_period_from_the_sections(hole, part, deg) -> None:
    from teachfit.tasks.mesh.sections import _rz_tolerance

    walls = _walls(hole)
    clearance = float(walls.distance(part))
    period = rz_period_of(walls, part, _rz_tolerance(walls, part), clearance)
    assert np.degrees(period) == pytest.approx(deg)


def test_a_round_peg_in_a_round_bore_may_turn_freely() -> None:
    from teachfit.tasks.mesh.holes import best_opening
    from teachfit.tasks.mesh.sections import fit_of

    peg = trimesh.creation.cylinder(radius=0.004, height=0.02, sections=64)
    peg.apply_translation([0.0, 0.0, 0.01])  # tip at the TCP
    plate = _box((-0.02, -0.02, 0.0), (0.02, 0.02, 0.009))
    bore = manifold3d.Manifold.cylinder(0.011, 0.005, 0.005, 64).translate([0.0, 0.0, -0.001])
    fixed = from_manifold(plate - bore)  # 1 mm clearance per side
    opening = best_opening(fixed, peg, np.array([0.0, 0.0, -1.0]))
    assert opening.pos == pytest.approx([0.0, 0.0, 0.009], abs=1e-6)
    fixed.apply_translation(-opening.pos)
    fit = fit_of(fixed, peg, 0.005, "t")
    assert fit.rz_period == 0.0 and fit.stop_depth == pytest.approx(0.009, abs=1e-6)
