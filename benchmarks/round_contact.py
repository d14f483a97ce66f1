"""Round-peg contact two ways: exact ring sectors vs MuJoCo's own non-convex (SDF) collision.

Usage: ``python benchmarks/round_contact.py [--steps 2000] [--repeats 3] [--folder DIR]
[--markdown FILE]``

The cell is the ``round-peg`` example (:mod:`teachfit.tasks.mesh.examples`): an 8 mm round
peg, no chamfer, in an 8.2 mm through bore of a 9 mm plate (0.1 mm clearance per side). It is
built both ways and compared with the built-in ``peg2d``:

* ``sectors``: the mesh task as ``teachfit tasks new`` builds it, the plate cut into ring
  sectors and boxes (:mod:`teachfit.tasks.mesh.revolved`), the peg its own convex hull;
* ``sdf``: both meshes as single ``type="sdf"`` geoms, MuJoCo colliding them through the
  signed distance field it computes from each mesh (MuJoCo 3.3+ needs no plugin for that;
  the wheel's ``libsdf_plugin.so`` holds analytic shapes only, no ``sdflib`` mesh plugin).

Columns: convex pieces of the fixed part; clearance kept, the fidelity check of the pieces
(:mod:`teachfit.tasks.mesh.fidelity`; the SDF geom is the mesh itself); clearance felt, the
peg held 3 mm deep in the hole and pushed 5 N each way along x, half its travel (soft contact
lets it sink a few micrometres into the wall); build, the decomposition's wall time;
compile, MuJoCo's model compile; steps/s with the controller in the loop, in contact, from
the state ``teachfit bench sim`` measures from (the tool pressed onto the surface at the
teacher's start, sliding at 10 mm/s: :mod:`teachfit.robot.speed`), timed in CPU seconds of
this thread (on a shared machine other jobs' time does not count) and interleaved across the
three cells, best of ``--repeats``; and its ratio to ``peg2d``'s; contacts, the most seen.
``--markdown FILE`` appends the table with its provenance header
(:func:`teachfit.cli.common.append_markdown`).
"""

from __future__ import annotations

import argparse
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import trimesh

from teachfit.cli.common import append_markdown
from teachfit.robot.floating import build_scene
from teachfit.robot.speed import _pressed_robot
from teachfit.tasks.base import Task
from teachfit.tasks.mesh.examples import write_example
from teachfit.tasks.mesh.task import HELD_MASS, MeshScene, MeshTask, load_mesh_task
from teachfit.tasks.registry import load_task
from teachfit.tasks.scene.builder import add_geom, fixture_body
from teachfit.tasks.scene.mjcf import ContactParams, SceneXml, fmt


def _sdf_geom(
    parent: ET.Element,
    scene: SceneXml,
    name: str,
    mesh: trimesh.Trimesh,
    contact: ContactParams,
    **attrs: object,
) -> None:
    """A mesh asset with its triangles and an SDF geom of it (MuJoCo computes the field)."""
    faces = " ".join(str(int(i)) for i in np.asarray(mesh.faces).ravel())
    ET.SubElement(scene.asset, "mesh", name=name, vertex=fmt(mesh.vertices), face=faces)
    add_geom(parent, name, contact, type="sdf", mesh=name, **attrs)


class SdfScene(MeshScene):
    """The mesh task's two meshes as one SDF geom each."""

    def add_fixture(self, scene: SceneXml, contact: ContactParams) -> None:
        _sdf_geom(fixture_body(scene), scene, "fixed_sdf", self.task.cell.fixed, contact)

    def add_held_part(self, body: ET.Element, scene: SceneXml, contact: ContactParams) -> None:
        held = self.task.cell.held
        _sdf_geom(body, scene, "held_sdf", held, contact, material="tool", mass=HELD_MASS)


class SdfMeshTask(MeshTask):
    """A mesh task collided through SDFs instead of convex pieces."""

    scene_type = SdfScene


def felt_clearance(task: Task, depth: float = 0.003, force: float = 5.0) -> float:
    """Half the x travel (m) of the held part ``depth`` below the hole entry, free in x and y
    only (no gravity), pushed by ``force`` (N) along +x and then -x for 1.5 s each."""
    scene = SceneXml("push")
    scene.option.set("gravity", "0 0 0")
    builder = task.scene
    builder.add_fixture(scene, builder.contact)
    pos = task.hole2world.pos - np.array([0.0, 0.0, depth])
    body = ET.SubElement(scene.worldbody, "body", name="tool", pos=fmt(pos))
    for axis in ("1 0 0", "0 1 0"):
        ET.SubElement(body, "joint", type="slide", axis=axis, damping="20")
    builder.add_held_part(body, scene, builder.contact)
    m = mujoco.MjModel.from_xml_string(scene.to_string())
    d = mujoco.MjData(m)
    ends = []
    for sign in (1.0, -1.0):
        mujoco.mj_resetData(m, d)
        d.qfrc_applied[0] = sign * force
        for _ in range(1500):
            mujoco.mj_step(m, d)
        ends.append(float(d.qpos[0]))
    return (ends[0] - ends[1]) / 2


def compile_seconds(task: Task) -> float:
    """Wall time (s) of compiling the task's floating-tool scene."""
    xml = build_scene(task)
    t0 = time.perf_counter()
    mujoco.MjModel.from_xml_string(xml)
    return time.perf_counter() - t0


def cpu_speeds(tasks: list[Task], steps: int, repeats: int) -> list[tuple[float, int]]:
    """Best controlled steps per CPU second of each task, and the most contacts seen after."""
    best = [(0.0, 0)] * len(tasks)
    for _ in range(repeats):
        for k, task in enumerate(tasks):
            sim, _cmd = _pressed_robot(task, "floating")
            t0 = time.thread_time()
            sim.step(steps)
            rate = steps / max(time.thread_time() - t0, 1e-9)
            most = 0
            for _ in range(50):
                sim.step(1)
                mujoco.mj_forward(sim.model, sim.data)
                most = max(most, int(sim.data.ncon))
            best[k] = (max(best[k][0], rate), max(best[k][1], most))
    return best


def measure(folder: Path, steps: int, repeats: int) -> list[dict[str, object]]:
    """The table's rows: peg2d, the sectors and the SDF cells of the round-peg example."""
    path = write_example("round-peg", folder)
    t0 = time.perf_counter()
    sectors = load_mesh_task(path)
    built = time.perf_counter() - t0
    cell = sectors.cell
    sdf = SdfMeshTask(cell, sectors.params, sectors.name)
    peg2d = load_task("peg2d")
    n_sectors = int(getattr(peg2d.params, "n_sectors"))  # noqa: B009 (a peg2d field)
    rows: list[dict[str, object]] = [
        {"method": "peg2d (built-in)", "pieces": f"{n_sectors + 1}",
         "kept": "100 % (by construction)", "build": "-"},
        {"method": "sectors", "pieces": str(cell.fixed_pieces.n_pieces),
         "kept": f"{100 * cell.fidelity.kept:.0f} %",
         "build": f"{cell.fixed_pieces.seconds:.2f} s ({built:.2f} s cell)"},
        {"method": "sdf", "pieces": "1 (the mesh)", "kept": "- (the mesh itself)",
         "build": "0 s"},
    ]  # fmt: skip
    tasks: list[Task] = [peg2d, sectors, sdf]
    for row, task, (rate, contacts) in zip(
        rows, tasks, cpu_speeds(tasks, steps, repeats), strict=True
    ):
        row.update(
            felt=f"{1e3 * felt_clearance(task):.3f} mm",
            compile=f"{compile_seconds(task):.2f} s",
            rate=rate,
            contacts=str(contacts),
        )
    return rows


COLUMNS = ("method", "pieces", "kept", "felt", "build", "compile", "rate", "ratio", "contacts")
HEAD = (
    "method", "fixed pieces", "clearance kept", "clearance felt", "build", "compile",
    "steps/CPU s", "x peg2d", "contacts",
)  # fmt: skip


def table(rows: list[dict[str, object]]) -> list[list[str]]:
    """The rows as strings, steps/s with their ratio to the first row's (peg2d)."""
    ref = float(str(rows[0]["rate"]))
    out = []
    for r in rows:
        speed = float(str(r["rate"]))
        r = {**r, "rate": f"{speed:,.0f}", "ratio": f"{speed / ref:.2f}"}
        out.append([str(r[c]) for c in COLUMNS])
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--steps", type=int, default=2000, help="steps per speed measurement")
    ap.add_argument("--repeats", type=int, default=3, help="speed measurements (best counts)")
    ap.add_argument("--folder", type=Path, help="where to write the example (default: temp)")
    ap.add_argument("--markdown", type=Path, help="append the table to this markdown file")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        rows = table(measure(args.folder or Path(tmp), args.steps, args.repeats))
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(HEAD)]
    for line in [list(HEAD), *rows]:
        print("  ".join(c.rjust(w) for c, w in zip(line, widths, strict=True)))
    if args.markdown is not None:
        title = (
            "**Round-peg contact** (8 mm peg, 8.2 mm through bore, 0.1 mm per side; best of "
            f"{args.repeats} x {args.steps} steps, controller in the loop)"
        )
        lines = [title, "", "| " + " | ".join(HEAD) + " |", "|" + " --- |" * len(HEAD)]
        lines += ["| " + " | ".join(r) + " |" for r in rows]
        print(f"markdown appended to {append_markdown(args.markdown, chr(10).join(lines))}")


if __name__ == "__main__":
    main()
