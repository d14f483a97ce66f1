"""The mesh task kind on the two shipped examples: frames, fit, protocols, registry, MJCF."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from teachfit.core.geometry import Pose
from teachfit.robot.floating import build_scene
from teachfit.tasks.mesh.task import MeshTask
from teachfit.tasks.registry import get_task, load_task, search_dims_of


@pytest.fixture(scope="module")
def square(mesh_examples) -> MeshTask:
    task = load_task(mesh_examples["square-peg"])
    assert isinstance(task, MeshTask)
    return task


def test_square_peg_cell(square: MeshTask) -> None:
    cell = square.cell
    assert square.hole2world.pos == pytest.approx([0.0, 0.0, 0.015])
    assert cell.fit.clearance == pytest.approx(1e-4, abs=1e-6)  # 10.2 mm hole, 10 mm peg
    assert cell.fit.hole_depth == pytest.approx(0.010, abs=1e-5)
    assert cell.fixed_pieces.method == "boxes" and cell.held_pieces.method == "hull"
    assert cell.fidelity.kept == pytest.approx(1.0, abs=1e-3)
    assert np.degrees(cell.fit.rz_tolerance) == pytest.approx(1.16, abs=0.05)
    assert square.search_dims == ("x", "y") and square.rz_period == pytest.approx(np.pi / 2)


def test_ground_truth_and_detection(square: MeshTask) -> None:
    inside = square.hole2world.compose(Pose(np.array([0.0, 0.0, -0.007])))
    assert square.ground_truth_inserted(inside) and square.detect_success(inside)
    beside = square.hole2world.compose(Pose(np.array([0.001, 0.0, -0.007])))
    assert not square.ground_truth_inserted(beside)
    on_top = square.hole2world.compose(Pose(np.array([0.004, 0.0, 0.0])))
    assert not square.ground_truth_inserted(on_top)


def test_protocol_starts_stay_over_the_top(square: MeshTask) -> None:
    rng = np.random.default_rng(0)
    starts = square.protocol.protocol_starts("table1", 50, rng)
    starts += square.protocol.protocol_starts("skill", 4, rng)
    starts.append(square.protocol.teacher_start(rng))
    for s in starts:
        assert square.lateral_error(s) <= square.detection_radius + 1e-12
        assert s.pos[2] >= square.surface_z - 1e-12


def test_registry_loads_task_files_by_name(square: MeshTask, mesh_examples) -> None:
    name = square.name
    assert name.endswith("square-peg.toml")
    assert search_dims_of(name) == ("x", "y")
    assert search_dims_of(mesh_examples["usb"]) == ("x", "y", "rz")
    again = get_task(name, friction=0.5)  # what worker processes do with the name
    assert again.params.friction == 0.5 and again.cell is square.cell


def test_scene_has_one_geom_per_piece(mesh_examples) -> None:
    task = load_task(mesh_examples["usb"])
    model = mujoco.MjModel.from_xml_string(build_scene(task))
    names = [model.geom(i).name for i in range(model.ngeom)]
    assert sum(n.startswith("fixed_piece_") for n in names) == task.cell.fixed_pieces.n_pieces
    assert sum(n.startswith("held_piece_") for n in names) == task.cell.held_pieces.n_pieces
    assert task.rz_period == pytest.approx(np.pi)
