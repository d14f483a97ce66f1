"""Exact pieces of parts with round bores: ring sectors that keep the clearance, and the
parts that are no such thing going to the old paths."""

from __future__ import annotations

from pathlib import Path

import manifold3d
import numpy as np
import pytest
import trimesh

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.cell import build_cell
from teachfit.tasks.mesh.decompose import CoacdSettings, decompose
from teachfit.tasks.mesh.examples import round_peg, square_peg, usb, write_example
from teachfit.tasks.mesh.loading import from_manifold
from teachfit.tasks.mesh.revolved import find_bores, revolved_pieces, sector_count
from teachfit.tasks.mesh.spec import read_spec


def _mm(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    mesh.apply_scale(0.001)
    return mesh


def _plate_with(cutter: manifold3d.Manifold) -> trimesh.Trimesh:
    """A 40 x 40 x 9 mm plate (m) less ``cutter`` (mm, about the plate's z axis)."""
    plate = manifold3d.Manifold.cube([40.0, 40.0, 9.0]).translate([-20.0, -20.0, 0.0])
    return _mm(from_manifold(plate - cutter))


def _countersunk(diameter: float, sink: float, segments: int = 96) -> manifold3d.Manifold:
    bore = manifold3d.Manifold.cylinder(11.0, diameter / 2, diameter / 2, segments)
    cone = manifold3d.Manifold.cylinder(2 * sink, diameter / 2, diameter / 2 + 2 * sink, segments)
    return bore.translate([0.0, 0.0, -1.0]) + cone.translate([0.0, 0.0, 9.0 - sink])


def test_the_8_2_mm_bore_keeps_its_clearance(tmp_path: Path) -> None:
    cell = build_cell(read_spec(write_example("round-peg", tmp_path)))
    assert cell.fixed_pieces.method == "revolved" and cell.held_pieces.method == "hull"
    assert cell.held_pieces.n_pieces == 1  # the round peg is convex: one exact piece
    assert cell.fit.clearance == pytest.approx(1e-4, rel=0.01)  # 0.1 mm per side
    assert cell.fidelity.kept >= 0.95
    assert cell.fidelity.volume_ratio == pytest.approx(1.0, abs=2e-3)  # no overlaps
    # 32 + 40 sectors for the 8.2 and 12.2 mm bores, and the plate around them in boxes
    assert 72 < cell.fixed_pieces.n_pieces <= 72 + 48


def test_chamfered_countersink_is_one_convex_slab_of_sectors() -> None:
    plate = _plate_with(_countersunk(8.2, 1.0))
    (bore,) = find_bores(plate)
    np.testing.assert_allclose(bore.centre, [0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(bore.levels, [0.0, 0.008, 0.009], atol=1e-7)
    np.testing.assert_allclose(bore.radii, [0.0041, 0.0041, 0.0051], atol=1e-7)
    pieces = revolved_pieces(plate, 2e-5, 48)
    assert pieces is not None
    total = sum(trimesh.Trimesh(v, f).volume for v, f in pieces)
    # the pieces' polygonal bore circumscribes the circle the mesh's facets are inscribed in
    assert 0 <= plate.volume - total < 0.002 * plate.volume
    for v, f in pieces:
        piece = trimesh.Trimesh(v, f)
        assert piece.volume == pytest.approx(piece.convex_hull.volume, rel=1e-9)


def _cyl(height: float, r0: float, r1: float, x: float, z: float) -> manifold3d.Manifold:
    return manifold3d.Manifold.cylinder(height, r0, r1, 96).translate([x, 0.0, z])


@pytest.mark.parametrize(
    ("cutter", "n_bores"),
    [
        (_cyl(10.0, 4.1, 4.1, 3.0, 4.0), 1),  # blind, off the plate's centre
        (_cyl(11.0, 4.1, 4.1, 0.0, -1.0) + _cyl(5.0, 6.1, 6.1, 0.0, 6.0), 2),  # counterbore
        (_cyl(11.0, 4.1, 4.1, 0.0, -1.0) + _cyl(2.0, 5.1, 4.1, 0.0, -1.0), 1),  # bottom chamfer
        (_cyl(11.0, 4.1, 4.1, -5.0, -1.0) + _cyl(11.0, 4.1, 4.1, 5.0, -1.0), 2),  # 1.8 mm apart
    ],
    ids=["blind", "counterbore", "bottom-chamfer", "two-close-bores"],
)
def test_other_bores_are_cut_exactly(cutter: manifold3d.Manifold, n_bores: int) -> None:
    plate = _plate_with(cutter)
    bores = find_bores(plate)
    assert bores is not None and len(bores) == n_bores
    pieces = revolved_pieces(plate, 2e-5, 48)
    assert pieces is not None
    total = sum(trimesh.Trimesh(v, f).volume for v, f in pieces)
    assert 0 <= plate.volume - total < 0.002 * plate.volume


def test_bore_along_x_is_found_too() -> None:
    plate = _plate_with(_countersunk(8.2, 0.5))
    plate.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    pieces = revolved_pieces(plate, 2e-5, 48)
    assert pieces is not None
    total = sum(trimesh.Trimesh(v, f).volume for v, f in pieces)
    assert 0 <= plate.volume - total < 0.002 * plate.volume


@pytest.mark.parametrize(
    "cutter",
    [
        manifold3d.Manifold.cylinder(11.0, 4.1, 4.1, 6).translate([0.0, 0.0, -1.0]),  # hexagon
        manifold3d.Manifold.cylinder(11.0, 4.1, 4.1, 12).translate([0.0, 0.0, -1.0]),  # 12-gon
        manifold3d.Manifold.cylinder(20.0, 4.1, 4.1, 64).translate([18.0, 0.0, -1.0]),  # notch
    ],
    ids=["hexagon", "12-gon", "bore-cutting-the-edge"],
)
def test_parts_that_are_no_bored_block_go_to_the_old_paths(
    cutter: manifold3d.Manifold,
) -> None:
    plate = _plate_with(cutter)
    assert revolved_pieces(plate, 2e-5, 48) is None
    with pytest.raises(TaskError, match="round bores"):
        decompose(plate, CoacdSettings(method="revolved"), None, "plate")


def test_boss_and_shipped_examples_are_not_cut_into_sectors() -> None:
    boss = manifold3d.Manifold.cube([40.0, 40.0, 5.0]).translate([-20.0, -20.0, 0.0])
    boss = _mm(from_manifold(boss + manifold3d.Manifold.cylinder(10.0, 4.0, 4.0, 64)))
    assert revolved_pieces(boss, 2e-5, 48) is None  # a round face looking outward
    plug, _ = usb()
    assert revolved_pieces(_mm(plug), 2e-5, 48) is None  # slanted chamfers: coacd as before
    _, plate = square_peg()
    assert decompose(_mm(plate), CoacdSettings(), None, "plate").method == "boxes"
    peg, _ = round_peg()
    assert decompose(_mm(peg), CoacdSettings(), None, "peg").method == "hull"


@pytest.mark.parametrize("radius", [0.002, 0.0041, 0.0061, 0.025])
@pytest.mark.parametrize("widening", [5e-6, 2e-5, 1e-4])
def test_sector_count_is_the_smallest_multiple_of_8_within_the_widening(
    radius: float, widening: float
) -> None:
    n = sector_count(radius, widening)
    assert n % 8 == 0 and 16 <= n <= 256
    assert radius * (1 / np.cos(np.pi / n) - 1) <= widening or n == 256
    if n > 16:
        assert radius * (1 / np.cos(np.pi / (n - 8)) - 1) > widening
    assert sector_count(0.0041, 2e-5) == 32  # as many as peg2d's hole


def test_sector_chords_circumscribe_the_bore() -> None:
    plate = _plate_with(_countersunk(8.2, 0.5))
    pieces = revolved_pieces(plate, 2e-5, 48)
    assert pieces is not None
    near = [v for v, _ in pieces if np.linalg.norm(v[:, :2], axis=1).min() < 0.005]
    assert len(near) == sector_count(0.0046, 2e-5)
    # each sector's inner face is a chord whose midpoint lies on the circle (r = 4.1 mm below
    # the countersink): the polygon circumscribes the bore, widening it by <= 0.02 mm
    for v in near:
        bottom = v[np.isclose(v[:, 2], 0.0)]
        p0, p1 = bottom[np.argsort(np.linalg.norm(bottom[:, :2], axis=1))[:2], :2]
        assert np.linalg.norm((p0 + p1) / 2) == pytest.approx(0.0041, abs=1e-9)
        assert 0 < np.linalg.norm(p0) - 0.0041 <= 2e-5
