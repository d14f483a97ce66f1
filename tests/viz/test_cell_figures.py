"""Figures of mesh tasks at true scale: the hole's real outline and size, equal axes."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest

from teachfit.tasks.mesh.examples import write_example
from teachfit.tasks.mesh.outline import hole_outline
from teachfit.tasks.mesh.task import MeshTask, load_mesh_task
from teachfit.viz.cell_figures import cell_axes, cell_figure
from teachfit.viz.figures import _hole_patch


@pytest.fixture(scope="module")
def round_task(tmp_path_factory: pytest.TempPathFactory) -> MeshTask:
    return load_mesh_task(write_example("round-peg", tmp_path_factory.mktemp("round")))


def _labels(ax: plt.Axes) -> list[str]:
    return [h.get_label() for h in ax.get_legend_handles_labels()[0]]


def test_the_8_2_mm_bore_is_drawn_at_its_real_size(round_task: MeshTask) -> None:
    outline = hole_outline(round_task.cell)
    assert outline.round and outline.label() == "hole, Ø 8.20 mm"
    radii = np.linalg.norm(outline.xy - round_task.hole2world.pos[:2], axis=1)
    np.testing.assert_allclose(radii, 0.0041, atol=1.5e-6)  # the 128-gon bore, world frame
    fig, ax = plt.subplots()
    _hole_patch(ax, round_task, 1e3)  # the demonstrations' and executions' figures
    assert "hole, Ø 8.20 mm" in _labels(ax) and not any("4.0 mm" in s for s in _labels(ax))
    plt.close(fig)


def test_cell_figure_has_equal_axes_and_the_real_hole(round_task: MeshTask, tmp_path: Path) -> None:
    fig = cell_axes(round_task)
    view, top, zoom = fig.axes
    spans = [np.ptp(lim) for lim in (view.get_xlim(), view.get_ylim(), view.get_zlim())]
    np.testing.assert_allclose(spans, spans[0])
    np.testing.assert_allclose(view.get_box_aspect(), view.get_box_aspect()[0])
    assert top.get_aspect() == 1.0 and zoom.get_aspect() == 1.0
    assert "hole, Ø 8.20 mm" in _labels(top)
    assert np.ptp(zoom.get_xlim()) < 1.0  # the clearance's own scale: < 1 mm across
    assert "0.100 mm per side" in zoom.get_title()
    plt.close(fig)
    png = cell_figure(round_task, tmp_path / "cell.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
