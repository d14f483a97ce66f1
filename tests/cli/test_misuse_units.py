"""Misuse walk, units and sizes family: mesh tasks whose parts are in other units than declared,
degenerate, tiny or huge, with too many triangles, truncated, empty or sparse-huge files.

Every command that loads the task refuses each with exit status 2 and one line naming the
mesh file, no traceback, nothing written, and before any heavy work: the self-intersection
check and the decomposition are made to fail the test if they run, and for the files refused
unread, so is parsing the mesh.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
import trimesh
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.tasks.mesh import budget, cell, loading
from teachfit.tasks.mesh.examples import square_peg
from teachfit.tasks.mesh.spec import MeshTaskSpec, spec_to_toml

runner = CliRunner()


def _stl(path: Path, mesh: trimesh.Trimesh, scale: float = 1.0) -> None:
    mesh = mesh.copy()
    mesh.apply_scale(scale)
    path.write_bytes(mesh.export(file_type="stl"))


def _scaled(held: float, fixed: float) -> Callable[[Path, Path], None]:
    """The square-peg example's peg and plate written in mm times ``held`` / ``fixed``."""

    def write(held_path: Path, fixed_path: Path) -> None:
        peg, plate = square_peg()
        _stl(held_path, peg, held)
        _stl(fixed_path, plate, fixed)

    return write


def _held_bytes(make: Callable[[bytes], bytes]) -> Callable[[Path, Path], None]:
    """Plausible parts, then the held mesh's file replaced by ``make(its bytes)``."""

    def write(held_path: Path, fixed_path: Path) -> None:
        _scaled(1.0, 1.0)(held_path, fixed_path)
        held_path.write_bytes(make(held_path.read_bytes()))

    return write


def _sparse(held_path: Path, fixed_path: Path) -> None:
    _scaled(1.0, 1.0)(held_path, fixed_path)
    with held_path.open("r+b") as f:
        f.truncate(2 * 10**9)  # a 2 GB sparse file: no disk used


def _flat(held_path: Path, fixed_path: Path) -> None:
    _scaled(1.0, 1.0)(held_path, fixed_path)
    square = trimesh.Trimesh(
        [[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0]], [[0, 1, 2], [0, 2, 3]]
    )
    _stl(held_path, square)


def _fine_peg(held_path: Path, fixed_path: Path) -> None:
    _scaled(1.0, 1.0)(held_path, fixed_path)
    _stl(held_path, square_peg()[0].subdivide().subdivide().subdivide())  # 20 * 64 triangles


def _ascii_peg(held_path: Path, fixed_path: Path) -> None:
    _scaled(1.0, 1.0)(held_path, fixed_path)
    peg = square_peg()[0]
    for _ in range(4):
        peg = peg.subdivide()  # 20 * 256 triangles: over 1 MB of text
    held_path.write_text(peg.export(file_type="stl_ascii"))


#: (case, writer of the two meshes, declared units, words of the refusal, the file it names,
#: refused unread)
CASES = [
    (
        "mm declared as cm",
        _scaled(1, 1),
        "cm",
        'fixed part at most 600 mm); the meshes look like "mm"',
        "plate.stl",
        False,
    ),
    (
        "mm declared as m",
        _scaled(1, 1),
        "m",
        'held part at most 300 mm); the meshes look like "mm"',
        "peg.stl",
        False,
    ),
    ("mm declared as in", _scaled(1, 1), "in", 'set units = "mm"', "peg.stl", False),
    (
        "m declared as mm",
        _scaled(0.001, 0.001),
        "mm",
        'than a millimetre; the meshes look like "m"',
        "peg.stl",
        False,
    ),
    ("cm declared as m", _scaled(0.1, 0.1), "m", 'set units = "cm"', "peg.stl", False),
    (
        "held mm, fixed m",
        _scaled(1.2, 0.001),
        "mm",
        "export both parts in the same units",
        "plate.stl",
        False,
    ),
    ("huge fixture", _scaled(1, 10), "mm", "is 1000 x 640 x 150 mm", "plate.stl", False),
    ("tiny held part", _scaled(0.02, 1), "mm", "smaller than a millimetre", "peg.stl", False),
    ("flat held part", _flat, "mm", "not watertight", "peg.stl", False),
    (
        "too many triangles",
        _fine_peg,
        "mm",
        "has 1,280 triangles, more than the 1,000",
        "peg.stl",
        True,
    ),
    (
        "large ASCII STL",
        _ascii_peg,
        "mm",
        "MB, more than a mesh of 1,000 triangles",
        "peg.stl",
        True,
    ),
    (
        "truncated STL",
        _held_bytes(lambda b: b[: len(b) // 2]),
        "mm",
        "not a whole binary STL",
        "peg.stl",
        True,
    ),
    ("empty STL", _held_bytes(lambda b: b""), "mm", "is empty", "peg.stl", True),
    ("sparse 2 GB STL", _sparse, "mm", "is 2,000 MB", "peg.stl", True),
]

#: every command that loads a task file (the task file's path is substituted for TASK)
COMMANDS = [
    ("tasks", "show", "TASK"),
    ("tasks", "--xml", "TASK"),
    ("skill", "run", "--task", "TASK", "--starts", "1"),
    ("search", "run", "--task", "TASK", "--starts", "1"),
    ("assemble", "--task", "TASK", "--trials", "1"),
]


def _fail(what: str) -> Callable[..., None]:
    def boom(*args: object, **kwargs: object) -> None:
        raise AssertionError(f"{what} ran before the refusal")

    return boom


@pytest.fixture
def guarded_work(monkeypatch: pytest.MonkeyPatch) -> Callable[[bool], None]:
    """Make the heavy work fail the test; ``unread``: parsing the mesh too."""
    monkeypatch.setattr(budget, "MAX_TRIANGLES", 1000)
    monkeypatch.setattr(loading, "crossing_triangles", _fail("the self-intersection check"))
    monkeypatch.setattr(cell, "decompose", _fail("the decomposition"))

    def unread(on: bool) -> None:
        if on:
            monkeypatch.setattr(trimesh, "load", _fail("reading the mesh"))

    return unread


def _refused(argv: list[str], words: str, names: str) -> None:
    res = runner.invoke(app, argv)
    out = res.output.strip()
    where = f"teachfit {' '.join(argv)}"
    assert res.exit_code == 2, f"{where}: exit {res.exit_code} ({res.exception!r})\n{out}"
    assert "Traceback" not in out and len(out.splitlines()) == 1, f"{where}:\n{out}"
    assert out.startswith("error:") and words in out and names in out, f"{where}:\n{out}"


@pytest.mark.parametrize(
    ("case", "write", "units", "words", "names", "unread"), CASES, ids=[c[0] for c in CASES]
)
def test_every_command_refuses_the_task_in_one_line_before_heavy_work(
    tmp_path: Path,
    guarded_work: Callable[[bool], None],
    case: str,
    write: Callable[[Path, Path], None],
    units: str,
    words: str,
    names: str,
    unread: bool,
) -> None:
    held, fixed = tmp_path / "peg.stl", tmp_path / "plate.stl"
    write(held, fixed)
    spec = MeshTaskSpec(path=tmp_path / "t.toml", held_mesh=held, fixed_mesh=fixed, units=units)
    spec.path.write_text(spec_to_toml(spec))
    guarded_work(unread)
    before = sorted(tmp_path.rglob("*"))
    for command in COMMANDS:
        _refused([str(spec.path) if a == "TASK" else a for a in command], words, names)
    out = tmp_path / "new.toml"
    new = ["tasks", "new", str(out), "--held", str(held), "--fixed", str(fixed), "--units", units]
    _refused(new, words, names)
    assert sorted(tmp_path.rglob("*")) == before  # nothing written: no task file, no cache
