"""The planning parts as MuJoCo cells: disjoint boxes that rebuild the planning meshes."""

import itertools

import manifold3d
import numpy as np
import pytest

from teachfit.core.errors import TaskError
from teachfit.core.geometry import Pose
from teachfit.robot.registry import make_robot
from teachfit.tasks.geometry.parts_cell import PartsCell, PartsCellParams, part_boxes
from teachfit.tasks.registry import build_assembly


def _volume(lo, hi):
    return float(np.prod(np.clip(np.subtract(hi, lo), 0.0, None)))


@pytest.mark.parametrize("part", ["l-groove", "tenon"])
def test_boxes_are_disjoint_and_rebuild_the_planning_meshes(part):
    asm = build_assembly(part)
    for boxes, mesh in zip(part_boxes(part), (asm.moving, asm.fixed), strict=True):
        assert sum(_volume(lo, hi) for lo, hi in boxes) == pytest.approx(mesh.volume, rel=1e-6)
        for (a0, a1), (b0, b1) in itertools.combinations(boxes, 2):
            assert _volume(np.maximum(a0, b0), np.minimum(a1, b1)) < 1e-12
        solid = manifold3d.Manifold(
            manifold3d.Mesh(
                vert_properties=np.asarray(mesh.vertices, np.float32),
                tri_verts=np.asarray(mesh.faces, np.uint32),
            )
        )
        union = solid - solid  # empty
        for lo, hi in boxes:
            union = union + manifold3d.Manifold.cube(np.subtract(hi, lo)).translate(lo)
        assert (union - solid).volume() < 1e-9  # no box sticks out of the planning solid


def test_cell_places_the_fixed_part_by_the_capture_error():
    cell = PartsCell(PartsCellParams(part="l-groove", dx=0.002, dyaw=0.01))
    robot = make_robot("floating", cell, seed=0)  # the MJCF compiles
    assert robot.model.ngeom >= 8
    fixture = robot.model.body("fixture")
    assert np.allclose(fixture.pos, cell.g2world.pos) and fixture.pos[0] == pytest.approx(0.002)
    assert np.allclose(np.abs(fixture.quat), np.abs(cell.g2world.quat))
    assert cell.ground_truth_inserted(cell.hole2world)
    off = cell.hole2world.compose(Pose(np.array([0.006, 0.0, 0.0])))
    assert not cell.ground_truth_inserted(off)
    with pytest.raises(TaskError, match="part"):
        PartsCellParams(part="dovetail")
