"""``teachfit tasks``: the built-in tasks; ``new``, ``show``, ``example``, ``suite`` mesh tasks.

``teachfit tasks`` alone (or ``tasks list``) lists the built-in tasks with their parameters;
``tasks new`` writes a task file from a user's two meshes, ``tasks show`` describes one and
runs the cell checks, ``tasks example`` writes a shipped example, ``tasks suite`` the parts
suite (:mod:`teachfit.tasks.mesh.suite`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from teachfit.cli import options as o
from teachfit.cli.common import console, guarded
from teachfit.core.errors import TaskError

if TYPE_CHECKING:
    from teachfit.tasks.mesh.authoring import NewTask

tasks_app = typer.Typer(
    help="Tasks: the built-in ones, and tasks made from your own part meshes.",
    invoke_without_command=True,
)

_XML = typer.Option(help="print the MJCF scene of this task (name or .toml)")


def _list(xml: str | None) -> None:
    from teachfit.tasks.registry import TASKS, load_task, part_tables, task_names

    if xml is not None:
        from teachfit.cli.geometry_progress import geometry_progress
        from teachfit.robot.floating import build_scene

        with geometry_progress(f"loading task {xml}"):
            task = load_task(xml)
        console.print(build_scene(task), markup=False, highlight=False)
        return
    for name, cls in TASKS.items():
        task = cls()
        table = Table(title=f"{name}: {cls.description}", title_justify="left")
        table.add_column("parameter")
        table.add_column("default", justify="right")
        table.add_column("meaning")
        for pname, value, doc in task.param_table():
            table.add_row(pname, f"{value:g}" if isinstance(value, float) else str(value), doc)
        console.print(table)
        console.print(f"  search dims: {', '.join(cls.search_dims)}\n")
    for name, params in part_tables().items():
        console.print(f"{name}: {task_names()[name]} (Wang et al. 2019)")
        table = Table()
        table.add_column("dimension")
        table.add_column("default (m)", justify="right")
        for pname, value in params:
            table.add_row(pname, f"{value:g}")
        console.print(table)
        console.print("  plans over the moving part's 6-DOF pose (teachfit plan --task)\n")
    console.print("Your own parts: teachfit tasks new FILE.toml --held PART --fixed PART")


@tasks_app.callback()
@guarded
def tasks_main(ctx: typer.Context, xml: Annotated[str | None, _XML] = None) -> None:
    """List the built-in tasks with their parameters (``teachfit tasks`` alone)."""
    if ctx.invoked_subcommand is None:
        _list(xml)


@tasks_app.command("list")
@guarded
def tasks_list(xml: Annotated[str | None, _XML] = None) -> None:
    """List the built-in tasks with their parameters."""
    _list(xml)


def _vec(text: str | None, what: str) -> tuple[float, float, float] | None:
    return None if text is None else _vec3(text, what)


def _vec3(text: str, what: str) -> tuple[float, float, float]:
    try:
        values = tuple(float(v) for v in text.replace(",", " ").split())
    except ValueError:
        values = ()
    if len(values) != 3:
        raise TaskError(f"{what} wants three numbers 'X,Y,Z', got {text!r}")
    return values


def _print_new(new: NewTask, units: str) -> None:
    """What ``tasks new`` found and wrote: the openings (if several), the hole, the depths."""
    from teachfit.tasks.mesh.authoring import stop_text, yaw_text

    cell = new.cell
    if len(new.openings) > 1:
        console.print("openings in the fixed part (choose with --hole N or --hole-at X,Y,Z):")
        for i, o in enumerate(new.openings):
            mark = "  <- chosen" if i == new.chosen else ""
            console.print(f"  {i + 1}: {o.line(cell.spec.scale, units)}{mark}", markup=False)
    spec = cell.spec
    console.print(
        f"hole entry at {spec.hole_pos} {units} in the fixed mesh, insertion axis "
        f"{spec.insertion_axis}; {cell.fidelity.summary()}",
        markup=False,
    )
    console.print(f"aligned part stops at {stop_text(cell)}", markup=False)
    share = f"{1e3 * cell.success_depth:.3f} mm"
    console.print(f"success depth {share}; yaw period {yaw_text(cell)}", markup=False)
    console.print(f"wrote {new.path}; next: teachfit tasks show {new.path} --plot cell.png")


@tasks_app.command("new")
@guarded
def tasks_new(
    out: Annotated[Path, typer.Argument(help="task file to write (.toml)")],
    held: Annotated[Path, typer.Option(help="mesh of the part the robot holds (STL/OBJ/PLY)")],
    fixed: Annotated[Path, typer.Option(help="mesh of the part with the hole")],
    units: Annotated[str, typer.Option(help="units of the meshes: m, cm, mm or in")] = "m",
    hole_pos: Annotated[
        str | None, typer.Option(help="hole entry centre 'X,Y,Z' in the fixed mesh (units)")
    ] = None,
    insertion_axis: Annotated[
        str | None,
        typer.Option(
            help="insertion direction 'X,Y,Z' (default: any face's openings; -z with --hole-pos)"
        ),
    ] = None,
    hole: Annotated[
        int | None, typer.Option(help="take opening number N of the list printed (1-based)")
    ] = None,
    hole_at: Annotated[
        str | None, typer.Option(help="take the opening whose entry is nearest 'X,Y,Z' (units)")
    ] = None,
    search_dims: Annotated[str, typer.Option(help="searched DOF: x,y or x,y,rz")] = "x,y",
    success_depth: Annotated[
        float | None,
        typer.Option(help="insertion that counts (units; default 60 % of where the part stops)"),
    ] = None,
    rz_period: Annotated[
        float | None,
        typer.Option(
            help="the part's symmetry about its axis (deg; 0: any yaw; default: inferred)"
        ),
    ] = None,
    overwrite: Annotated[bool, typer.Option(help="replace an existing task file")] = False,
) -> None:
    """Write a task file for your own two meshes (hole frame inferred unless given)."""
    from teachfit.cli.geometry_progress import geometry_progress
    from teachfit.tasks.mesh.authoring import new_task_file

    axis = None if insertion_axis is None else _vec3(insertion_axis, "--insertion-axis")
    with geometry_progress("checking and decomposing the parts"):
        new = new_task_file(
            out,
            held,
            fixed,
            units,
            _vec(hole_pos, "--hole-pos"),
            axis,
            tuple(d.strip() for d in search_dims.split(",")),
            success_depth,
            rz_period,
            overwrite,
            hole,
            _vec(hole_at, "--hole-at"),
        )
    _print_new(new, units)


@tasks_app.command("show")
@guarded
def tasks_show(
    task_file: Annotated[str, typer.Argument(help="mesh task file (.toml)")],
    plot: Annotated[Path | None, typer.Option(help="write a figure of the cell (png)")] = None,
    checks: Annotated[bool, typer.Option(help="run the insertion checks in simulation")] = True,
) -> None:
    """Describe a mesh task's cell, run its checks and optionally plot it; exit 1 if a
    check fails."""
    from teachfit.cli.geometry_progress import geometry_progress
    from teachfit.tasks.mesh.authoring import describe
    from teachfit.tasks.mesh.task import MeshTask
    from teachfit.tasks.registry import load_task

    with geometry_progress("loading and decomposing the parts"):
        task = load_task(task_file)
    if not isinstance(task, MeshTask):
        raise TaskError(f'{task_file} is not a mesh task (task = "mesh")')
    table = Table(title=f"mesh task {task.name}", title_justify="left")
    table.add_column("what")
    table.add_column("value")
    for row in describe(task):
        table.add_row(*row)
    console.print(table)
    failed = 0
    if checks:
        from teachfit.robot.cell_checks import run_cell_checks

        with console.status("pushing the part in simulation"):
            results = run_cell_checks(task)
        for c in results:
            mark = "[green]pass[/]" if c.passed else "[red]FAIL[/]"
            console.print(f"{mark} {c.name}: depth {1e3 * c.depth:.2f} mm (expected {c.expected})")
            failed += not c.passed
    if plot is not None:
        from teachfit.viz.cell_figures import cell_figure

        console.print(f"figure -> {cell_figure(task, plot)}")
    if failed:
        raise typer.Exit(1)


@tasks_app.command("example")
@guarded
def tasks_example(
    name: Annotated[str, typer.Argument(help="square-peg, usb or round-peg")],
    folder: Annotated[Path, typer.Argument(help="folder to write the meshes and task file")],
) -> None:
    """Write a shipped example mesh task (meshes generated by our code) into a folder."""
    from teachfit.tasks.mesh.examples import write_example

    path = write_example(name, folder)
    console.print(f"wrote {path}; try: teachfit tasks show {path} --plot cell.png")


@tasks_app.command("suite")
@guarded
def tasks_suite(
    out: Annotated[
        Path, typer.Argument(metavar="FOLDER", help="folder to write the meshes and task files")
    ],
    parts: Annotated[
        str, typer.Option(help="parts of the suite, comma-separated (default: all)")
    ] = "",
    clearance: o.SuiteClearance = 0.2,
) -> None:
    """Write the industrial parts suite (NIST task board sizes, ISO 286 H7/g6 fits simulated
    at 0.2 mm clearance; meshes generated by our code) into a folder: one task file per part."""
    from teachfit.tasks.mesh.suite import PARTS, write_suite

    names = [p.strip() for p in parts.split(",") if p.strip()] or None
    for path in write_suite(out, names, clearance):
        console.print(f"wrote {path}: {PARTS[path.stem].at_clearance(clearance).describe()}")
