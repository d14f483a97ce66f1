"""Convex pieces of part meshes: exact boxes, coacd with its on-disk cache, fidelity."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.decompose import CoacdSettings, decompose
from teachfit.tasks.mesh.examples import square_peg, usb
from teachfit.tasks.mesh.fidelity import Fidelity, decomposition_fidelity, require_fidelity
from teachfit.tasks.mesh.planar import box_pieces
from teachfit.tasks.registry import load_task


def test_rectilinear_plate_is_cut_exactly_into_boxes() -> None:
    _, plate = square_peg()
    plate.apply_scale(0.001)
    pieces = box_pieces(plate, 64)
    assert pieces is not None and 3 <= len(pieces) <= 20
    assert sum(p.volume for p in pieces) == pytest.approx(plate.volume, rel=1e-9)
    union = trimesh.boolean.union(pieces, engine="manifold")
    assert union.volume == pytest.approx(plate.volume, rel=1e-6)  # no overlaps (float32 union)


def test_slanted_part_goes_to_coacd_and_is_cached(tmp_path: Path) -> None:
    plug, _ = usb()  # a chamfered tongue under a housing: not rectilinear, not convex
    plug.apply_scale(0.001)
    assert box_pieces(plug, 64) is None
    settings = CoacdSettings(mcts_iterations=20, resolution=500)
    first = decompose(plug, settings, tmp_path, "plug")
    assert first.method == "coacd" and not first.cached and first.n_pieces >= 2
    assert sorted(p.name.rsplit(".", 1)[1] for p in tmp_path.iterdir()) == ["json", "npz"]
    again = decompose(plug, settings, tmp_path, "plug")
    assert again.cached and again.n_pieces == first.n_pieces
    for (v1, f1), (v2, f2) in zip(first.pieces, again.pieces, strict=True):
        assert np.array_equal(v1, v2) and np.array_equal(f1, f2)
    with np.load(next(tmp_path.glob("*.npz")), allow_pickle=False) as z:  # no pickle inside
        assert z["n_vertices"].sum() == len(z["vertices"])


def test_boxes_method_refuses_a_slanted_part() -> None:
    plug, _ = usb()
    plug.apply_scale(0.001)
    with pytest.raises(TaskError, match="rectilinear"):
        decompose(plug, CoacdSettings(method="boxes"), None, "plug")


def test_a_decomposition_that_closes_the_clearance_is_an_error(mesh_examples) -> None:
    task = load_task(mesh_examples["square-peg"])
    cell = task.cell
    z = cell.hole2world.pos
    hull = [np.asarray(cell.fixed.convex_hull.vertices) - z]  # one hull: the holes are gone
    fixed_h = cell.fixed.copy()
    fixed_h.apply_translation(-z)
    fid = decomposition_fidelity(
        fixed_h, hull, cell.held_pieces_tcp(), task.success_depth, cell.fit.clearance
    )
    assert fid.pieces_clearance == 0.0 and fid.kept == 0.0
    with pytest.raises(TaskError, match="narrows the hole"):
        require_fidelity(fid, "t.toml")
    require_fidelity(Fidelity(1e-4, 0.9e-4, 1.0), "t.toml")  # 90 % kept is fine
