"""Mesh task files and their bad input: one clear error per mistake, naming file and fix."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh.cell import build_cell
from teachfit.tasks.mesh.examples import chamfered_bar
from teachfit.tasks.mesh.spec import MeshTaskSpec, read_spec, spec_to_toml


def _cell_files(tmp_path: Path, held: trimesh.Trimesh, fixed: trimesh.Trimesh, **kw) -> Path:
    held.export(tmp_path / "held.stl")
    fixed.export(tmp_path / "fixed.stl")
    spec = MeshTaskSpec(
        path=tmp_path / "t.toml",
        held_mesh=tmp_path / "held.stl",
        fixed_mesh=tmp_path / "fixed.stl",
        **kw,
    )
    spec.path.write_text(spec_to_toml(spec))
    return spec.path


def _block_with_hole(side: float) -> trimesh.Trimesh:
    """A 40 x 40 x 10 mm block (in m) with a ``side`` (m) square through-pocket 6 mm deep."""
    from teachfit.tasks.mesh.examples import _box
    from teachfit.tasks.mesh.loading import from_manifold

    solid = _box((-0.02, -0.02, 0.0), (0.02, 0.02, 0.01))
    solid = solid - _box((-side / 2, -side / 2, 0.004), (side / 2, side / 2, 0.011))
    return from_manifold(solid)


PEG = chamfered_bar(0.003, 0.003, 0.02, 0.0003)


def test_spec_round_trips_and_resolves_paths_against_the_file(tmp_path: Path) -> None:
    path = _cell_files(
        tmp_path, PEG, _block_with_hole(0.0062), hole_pos=(0.0, 0.0, 0.01), search_dims=("x", "y")
    )
    spec = read_spec(path)
    assert spec.held_mesh == tmp_path / "held.stl"  # relative path in the file
    assert spec.hole_pos == (0.0, 0.0, 0.01) and spec.units == "m"
    cell = build_cell(spec)
    assert cell.fit.clearance == pytest.approx(0.0001, abs=1e-6)
    assert cell.fit.hole_depth == pytest.approx(0.006, abs=1e-5)
    assert cell.hole2world.pos == pytest.approx([0.0, 0.0, 0.01])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('task = "mesh"\n[held]\nmesh = "a.stl"\n', "needs a [held] and a [fixed]"),
        ('task = "mesh"\nunits = "km"\n', "units must be one of"),
        ('task = "mesh"\ncolour = 1\n', "unknown key(s) ['colour']"),
        ('task = "mesh"\n[held]\nmesh="a.stl"\n[fixed]\nmesh="b.stl"\nhole_pos=[1]\n', "three"),
        ("task = [", "not valid TOML"),
    ],
)
def test_bad_task_files_are_one_clear_error(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(TaskError, match="bad.toml") as err:
        read_spec(path)
    assert message in str(err.value) and "\n" not in str(err.value)


def _error(tmp_path: Path, held: trimesh.Trimesh, fixed: trimesh.Trimesh, **kw) -> str:
    path = _cell_files(tmp_path, held, fixed, **kw)
    with pytest.raises(TaskError) as err:
        build_cell(read_spec(path))
    assert "t.toml" in str(err.value) and "\n" not in str(err.value)
    return str(err.value)


def test_missing_and_unreadable_meshes(tmp_path: Path) -> None:
    path = _cell_files(tmp_path, PEG, _block_with_hole(0.0062), hole_pos=(0, 0, 0.01))
    (tmp_path / "held.stl").write_bytes(b"solid nothing\nendsolid\n")
    with pytest.raises(TaskError, match="holds no triangles|cannot read"):
        build_cell(read_spec(path))
    (tmp_path / "held.stl").unlink()
    with pytest.raises(TaskError, match="held.stl does not exist"):
        build_cell(read_spec(path))


def test_open_and_self_intersecting_meshes_are_rejected(tmp_path: Path) -> None:
    open_box = trimesh.creation.box((0.006, 0.006, 0.02))
    open_box.update_faces(np.arange(len(open_box.faces)) != 0)
    assert "not watertight (3 open edge(s))" in _error(tmp_path, open_box, _block_with_hole(0.0062))
    a = trimesh.creation.box((0.006, 0.006, 0.02))
    b = trimesh.creation.box((0.006, 0.006, 0.02))
    b.apply_translation([0.002, 0.0, 0.0])
    overlapping = trimesh.util.concatenate([a, b])
    assert "self-intersecting" in _error(tmp_path, overlapping, _block_with_hole(0.0062))


def test_mm_mesh_declared_as_metres(tmp_path: Path) -> None:
    peg_mm = PEG.copy()
    peg_mm.apply_scale(1000.0)  # a 20 mm peg written in mm, read as m: a 20 m peg
    assert "set units" in _error(tmp_path, peg_mm, _block_with_hole(0.0062))


def test_hole_frame_outside_or_inside_the_part(tmp_path: Path) -> None:
    msg = _error(tmp_path, PEG, _block_with_hole(0.0062), hole_pos=(0.05, 0.0, 0.01))
    assert "outside the fixed part" in msg
    msg = _error(tmp_path, PEG, _block_with_hole(0.0062), hole_pos=(0.015, 0.0, 0.01))
    assert "inside solid material" in msg


def test_held_part_larger_than_the_hole(tmp_path: Path) -> None:
    msg = _error(tmp_path, PEG, _block_with_hole(0.0058), hole_pos=(0, 0, 0.01))
    assert "larger than the hole" in msg
