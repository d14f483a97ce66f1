"""Bounds on part meshes: size and triangle count before reading, plausible part sizes before
the solid checks, and the self-intersection check's broad phase (slabs, progress)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
import trimesh

from teachfit.core.errors import TaskError
from teachfit.tasks.mesh import budget, crossing, loading
from teachfit.tasks.mesh.examples import square_peg
from teachfit.tasks.mesh.loading import load_parts
from teachfit.tasks.mesh.progress import reporting

WHERE = "t.toml [held] mesh"


@pytest.fixture
def no_reading(monkeypatch: pytest.MonkeyPatch) -> None:
    """Fail the test if a mesh is parsed at all (a refusal must come before)."""

    def boom(*args: object, **kwargs: object) -> None:
        raise AssertionError("the mesh was read")

    monkeypatch.setattr(trimesh, "load", boom)


def _parts(tmp_path: Path, scale: float = 1.0) -> tuple[Path, Path]:
    """The square-peg example's peg and plate (mm) times ``scale``, as binary STL."""
    peg, plate = square_peg()
    paths = (tmp_path / "peg.stl", tmp_path / "plate.stl")
    for mesh, path in zip((peg, plate), paths, strict=True):
        mesh = mesh.copy()
        mesh.apply_scale(scale)
        mesh.export(path)
    return paths


def test_a_binary_stl_counting_too_many_triangles_is_refused_unread(
    tmp_path: Path, no_reading: None
) -> None:
    path = tmp_path / "big.stl"
    n = budget.MAX_TRIANGLES + 1
    with path.open("wb") as f:  # a sparse file: the header's count and a matching size
        f.write(b"\0" * 80 + n.to_bytes(4, "little"))
        f.truncate(84 + 50 * n)
    with pytest.raises(TaskError, match=f"big.stl has {n:,} triangles.*decimate") as err:
        budget.check_mesh_file(path, WHERE)
    assert str(err.value).startswith(WHERE) and "\n" not in str(err.value)


def test_a_huge_sparse_file_is_refused_by_its_size(tmp_path: Path, no_reading: None) -> None:
    path = tmp_path / "huge.stl"
    with path.open("wb") as f:
        f.truncate(2 * 10**9)  # 2 GB of zeros, no disk used
    with pytest.raises(TaskError, match="huge.stl is 2,000 MB, more than a mesh of"):
        budget.check_mesh_file(path, WHERE)


def test_truncated_and_empty_stl_are_refused(tmp_path: Path, no_reading: None) -> None:
    data = trimesh.creation.box((0.01, 0.01, 0.01)).export(file_type="stl")
    path = tmp_path / "cut.stl"
    path.write_bytes(data[:-30])
    with pytest.raises(TaskError, match=r"not a whole binary STL \(its header counts 12 "):
        budget.check_mesh_file(path, WHERE)
    path.write_bytes(b"")
    with pytest.raises(TaskError, match="cut.stl is empty"):
        budget.check_mesh_file(path, WHERE)


def test_text_meshes_are_bounded_by_size_and_by_count_once_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(budget, "MAX_TRIANGLES", 100)
    ball = trimesh.creation.icosphere(2, 0.01)  # 320 triangles
    text = tmp_path / "ball.stl"
    text.write_bytes(ball.export(file_type="stl_ascii").encode())
    with pytest.raises(TaskError, match="ball.stl is 0 MB, more than a mesh of 100 triangles"):
        budget.check_mesh_file(text, WHERE)
    obj = tmp_path / "ball.obj"
    obj.write_text(ball.export(file_type="obj"))
    budget.check_mesh_file(obj, WHERE)  # small enough a file: read, then counted
    with pytest.raises(TaskError, match="ball.obj has 320 triangles, more than the 100"):
        loading.read_mesh(obj, WHERE)
    ply = tmp_path / "ball.ply"
    ply.write_bytes(ball.export(file_type="ply"))
    with pytest.raises(TaskError, match="ball.ply has 320 triangles"):
        budget.check_mesh_file(ply, WHERE)  # the header's count


def test_an_ascii_stl_named_in_utf8_is_text_not_a_truncated_binary(tmp_path: Path) -> None:
    text = trimesh.creation.box((0.01, 0.01, 0.01)).export(file_type="stl_ascii")
    path = tmp_path / "teil.stl"
    path.write_bytes(text.replace("solid", "solid Bauteil_ü", 1).encode())
    budget.check_mesh_file(path, WHERE)
    assert len(loading.read_mesh(path, WHERE).faces) == 12


@pytest.mark.parametrize(
    ("scale", "units", "words", "fits"),
    [
        (1.0, "cm", "1000 x 640 x 15", "mm"),  # mm meshes declared as cm: a 1 m plate
        (1.0, "m", "10000 x 10000 x 30000 mm", "mm"),  # mm declared as m: a 30 m peg
        (1.0, "in", "larger than a robot cell", "mm"),
        (0.001, "mm", "smaller than a millimetre", "m"),  # metres declared as mm
        (0.1, "m", "1000 x 1000 x 3000 mm", "cm"),  # cm declared as m
    ],
)
def test_implausible_sizes_name_the_units_that_fit_before_any_solid_check(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    scale: float,
    units: str,
    words: str,
    fits: str,
) -> None:
    def boom(*args: object, **kwargs: object) -> None:
        raise AssertionError("solid checks ran before the size check")

    monkeypatch.setattr(loading, "check_solid", boom)
    held, fixed = _parts(tmp_path, scale)
    with pytest.raises(TaskError) as err:
        load_parts(held, fixed, units, tmp_path / "t.toml")
    message = str(err.value)
    assert words in message and f'set units = "{fits}"' in message, message
    assert message.startswith(f"{tmp_path / 't.toml'} [") and "\n" not in message


def test_parts_in_different_units_are_named_as_such(tmp_path: Path) -> None:
    held, _ = _parts(tmp_path, 1.2)  # mm: a 36 mm peg
    (tmp_path / "m").mkdir()
    _, fixed = _parts(tmp_path / "m", 0.001)  # m: a 0.1 m plate
    with pytest.raises(TaskError, match='looks like "mm", the other part\'s not: export both'):
        load_parts(held, fixed, "m", tmp_path / "t.toml")


def test_plausible_parts_load_in_metres(tmp_path: Path) -> None:
    held, fixed = _parts(tmp_path)
    peg, plate = load_parts(held, fixed, "mm", tmp_path / "t.toml")
    assert peg.extents == pytest.approx([0.01, 0.01, 0.03])
    assert plate.extents == pytest.approx([0.1, 0.064, 0.015])


def _folded_box(subdivisions: int) -> trimesh.Trimesh:
    """A 6 x 6 x 20 mm box (m) with one corner pulled through the opposite side, subdivided."""
    box = trimesh.creation.box((0.006, 0.006, 0.02))
    v = box.vertices.copy()
    v[np.argmax(v @ [1.0, 1.0, 1.0])] = [-0.006, -0.006, -0.015]
    folded = trimesh.Trimesh(v, box.faces, process=False)
    for _ in range(subdivisions):
        folded = folded.subdivide()
    return folded


def test_crossings_are_found_across_slabs_with_progress(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(crossing, "CHUNK", 500)
    folded = _folded_box(3)  # 768 triangles: two slabs
    seen: list[tuple[str, int, int]] = []
    with reporting(lambda what, done, total: seen.append((what, done, total))):
        found = crossing.crossing_triangles(folded, "folded.stl")
    assert found is not None and found[0] > 0
    assert np.all(folded.bounds[0] <= found[1]) and np.all(found[1] <= folded.bounds[1])
    label = "self-intersection check folded.stl"
    assert seen == [(label, 1, 2), (label, 2, 2)]


@pytest.mark.parametrize(
    "mesh",
    [
        trimesh.creation.cylinder(0.005, 0.02, sections=400),  # caps: fans of 400 slivers
        trimesh.creation.icosphere(4, 0.01),
        trimesh.creation.box((0.001, 0.1, 0.05)).subdivide().subdivide(),  # thin slab
    ],
    ids=["fan-capped cylinder", "sphere", "thin slab"],
)
def test_touching_neighbours_are_no_crossing(mesh: trimesh.Trimesh) -> None:
    assert crossing.crossing_triangles(mesh) is None


def test_a_sparse_file_named_in_a_task_costs_nothing(tmp_path: Path, no_reading: None) -> None:
    held, fixed = _parts(tmp_path)
    with held.open("r+b") as f:
        f.truncate(3 * 10**9)
    with pytest.raises(TaskError, match="peg.stl is 3,000 MB"):
        load_parts(held, fixed, "mm", tmp_path / "t.toml")
    assert os.stat(held).st_blocks * 512 < 10**6  # still sparse: nothing was written


def test_building_a_cell_reports_its_stages(mesh_examples: dict[str, str]) -> None:
    from teachfit.tasks.mesh.cell import build_cell
    from teachfit.tasks.mesh.spec import read_spec

    seen: list[tuple[str, int, int]] = []
    with reporting(lambda what, done, total: seen.append((what, done, total))):
        build_cell(read_spec(mesh_examples["usb"]))
    stages = [(done, total) for what, done, total in seen if what.startswith("building")]
    assert stages == [(0, 4), (1, 4), (2, 4), (3, 4), (4, 4)]
    assert ("self-intersection check usb_plug.stl", 1, 1) in seen


def test_a_part_too_fine_for_coacd_is_refused_before_it_runs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import importlib

    decompose = importlib.import_module("teachfit.tasks.mesh.decompose")

    def never(*_: object) -> None:
        raise AssertionError("coacd ran")

    monkeypatch.setattr(decompose, "_run_coacd", never)
    monkeypatch.setattr(decompose, "COACD_MAX_TRIANGLES", 2_000)
    ring = trimesh.creation.torus(0.02, 0.005, major_sections=64, minor_sections=24)
    assert len(ring.faces) > 2_000 and not decompose.is_convex(ring)
    with pytest.raises(TaskError, match="decimate the part below 2,000 triangles"):
        decompose.decompose(ring, decompose.CoacdSettings(), None, "ring")
