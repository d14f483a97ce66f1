"""Tasks built from a user's CAD meshes: a TOML task file naming a held and a fixed part.

:mod:`.spec` (the task file), :mod:`.loading` (meshes and their checks), :mod:`.sections`
(hole, footprint and clearance from cross-sections), :mod:`.holes` (the openings on any
face), :mod:`.decompose` (convex pieces for MuJoCo: exact boxes (:mod:`.planar`), exact ring
sectors for round bores (:mod:`.revolved`), else ``coacd``, cached by content hash),
:mod:`.fidelity` (the clearance the pieces keep), :mod:`.cell` (placement), :mod:`.task`
(:class:`MeshTask`), :mod:`.outline` (the hole's outline for figures) and :mod:`.examples`.
"""

from teachfit.tasks.mesh.cell import MeshCell, build_cell
from teachfit.tasks.mesh.decompose import CoacdSettings, Decomposition, decompose
from teachfit.tasks.mesh.examples import EXAMPLES, write_example
from teachfit.tasks.mesh.fidelity import Fidelity
from teachfit.tasks.mesh.holes import infer_hole
from teachfit.tasks.mesh.sections import HoleFit
from teachfit.tasks.mesh.spec import MeshTaskSpec, read_spec, spec_to_toml
from teachfit.tasks.mesh.task import MeshParams, MeshTask, load_mesh_task

__all__ = [
    "EXAMPLES",
    "CoacdSettings",
    "Decomposition",
    "Fidelity",
    "HoleFit",
    "MeshCell",
    "MeshParams",
    "MeshTask",
    "MeshTaskSpec",
    "build_cell",
    "decompose",
    "infer_hole",
    "load_mesh_task",
    "read_spec",
    "spec_to_toml",
    "write_example",
]
