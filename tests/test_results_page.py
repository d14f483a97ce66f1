"""BENCHMARKS.md is what ``benchmarks/results_page.py`` builds from the committed results."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

from teachfit.cli import provenance as pv

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "benchmarks" / "results_page.py"


def _script() -> ModuleType:
    spec = importlib.util.spec_from_file_location("results_page", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_committed_page_is_what_the_results_give() -> None:
    rp = _script()
    page = (ROOT / "BENCHMARKS.md").read_text(encoding="utf-8")
    assert page == rp.build(rp.PAGE.read_text(encoding="utf-8")), (
        "BENCHMARKS.md is not generated from benchmarks/results/: run "
        "python benchmarks/results_page.py"
    )
    assert page.count("\n") <= 600
    runs = pv.blocks(page)
    assert runs and all(p.command.startswith(("teachfit ", "python ")) for p, _ in runs)


def test_a_section_shows_the_newest_run_of_its_file(tmp_path) -> None:
    rp = _script()
    old = pv.header(pv.Provenance("teachfit bench sim", "0.1.0", "aaa1111", "2026-12-01", "x", "2"))
    new = pv.header(pv.Provenance("teachfit bench sim", "0.1.0", "bbb2222", "2026-12-04", "x", "2"))
    (tmp_path / "sim.md").write_text(f"{old}\n\n## Old\n| 1 |\n\n{new}\n\n## New\n| 2 |\n")
    text = rp.build("# B\n\n<!-- include sim.md -->\n\ntail\n", tmp_path)
    assert "| 2 |" in text and "| 1 |" not in text and "#### New" in text
    assert "commit=bbb2222" in text and text.endswith("tail\n")
    assert rp.prune("<!-- include sim.md -->", tmp_path) == [tmp_path / "sim.md"]
    assert len(pv.blocks((tmp_path / "sim.md").read_text())) == 1
    assert rp.build("<!-- include sim.md -->", tmp_path).endswith("| 2 |\n")


def test_a_missing_or_unheaded_result_file_is_named(tmp_path) -> None:
    rp = _script()
    with pytest.raises(rp.PageError, match="gone.md: missing"):
        rp.build("<!-- include gone.md -->", tmp_path)
    (tmp_path / "bare.md").write_text("| a |\n")
    with pytest.raises(rp.PageError, match="bare.md: no provenance header"):
        rp.build("<!-- include bare.md -->", tmp_path)


def test_the_page_shows_only_command_output() -> None:
    """A table copied from an earlier record (``source=transcribed``) is history: it belongs
    in the notes, not among the current figures."""
    rp = _script()
    page = rp.build(rp.PAGE.read_text(encoding="utf-8"))
    assert "<!-- teachfit-run source=command " in page
    assert "<!-- teachfit-run source=transcribed" not in page
