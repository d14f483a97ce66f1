"""``teachfit demo ...``: record, import, export and show demonstrations."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, TypeVar

import typer
from rich.markup import escape
from rich.table import Table

from teachfit.cli import options as o
from teachfit.cli.common import (
    HostOpt,
    RealtimeOpt,
    ReflexForceOpt,
    RobotOpt,
    check_output,
    console,
    guarded,
    robot_options,
)
from teachfit.cli.recording import show_run_log
from teachfit.cli.tables import print_table
from teachfit.core.errors import DatasetError, TeachfitError
from teachfit.demonstrations.column_map import bare
from teachfit.demonstrations.dataset import (
    append_dataset,
    check_appendable,
    dataset_summary,
    read_dataset,
    read_demo,
    write_dataset,
)
from teachfit.demonstrations.export import export_csv
from teachfit.demonstrations.frames import FrameTransform
from teachfit.demonstrations.importing import ImportOptions, ImportResult, build_demos
from teachfit.demonstrations.log_reading import LogSource, read_robot_log
from teachfit.demonstrations.plausibility import CHECKS
from teachfit.demonstrations.segment import Segmenter
from teachfit.execution.recording import is_run_log
from teachfit.execution.teacher import PATTERNS, BlindTeacher, TeacherStyle
from teachfit.tasks.registry import TASKS, load_task

if TYPE_CHECKING:
    from teachfit.robot.franka.hand import Guide

T = TypeVar("T")
app = typer.Typer(help="Record, import and inspect demonstrations.", no_args_is_help=True)


@app.command("record")
@guarded
def record(
    task: Annotated[str, o.task()] = "peg2d",
    count: o.Count = 3,
    seed: Annotated[int, o.seed("the simulated teacher's starts and search")] = 0,
    out: Annotated[Path, typer.Option(help="HDF5 file to write")] = Path("demos.h5"),
    pattern: Annotated[str, typer.Option(help=f"search pattern: {', '.join(PATTERNS)}")] = "sweep",
    append: o.Append = False,
    overwrite: o.Overwrite = False,
    robot: RobotOpt = "floating",
    host: HostOpt = None,
    realtime: RealtimeOpt = True,
    reflex_force: ReflexForceOpt = None,
    duration: Annotated[
        float | None,
        typer.Option(min=0, help="real robot: seconds to record (default: until Ctrl-C)"),
    ] = None,
    hand: Annotated[
        Path | None,
        typer.Option(
            help="the Franka twin only: a scripted hand guides the arm (CSV t,x,y,press: s, m "
            "in the hole frame, N; python -m teachfit.robot.franka.hand writes one)"
        ),
    ] = None,
    n: o.CountOld = None,
) -> None:
    """Record demonstrations: the simulated blind teacher on a simulated robot, or a person
    guiding a real robot (--robot franka --host ADDRESS; Ctrl-C ends it, every sample kept),
    or on the Franka twin a scripted hand (--hand guide.csv)."""
    from teachfit.robot.registry import ROBOTS, make_robot

    count = o.pick(count, n)
    the_task = load_task(task)
    _check_target(out, append, overwrite)
    real = robot in ROBOTS and not ROBOTS[robot].simulated
    scripted = _scripted_hand(hand, real, host, duration)
    if real:
        from teachfit.demonstrations.kinesthetic import record_demonstration

        arm = make_robot(
            robot, the_task, **robot_options(host, realtime, reflex_force=reflex_force)
        )
        try:
            console.print(
                "guide the arm; Ctrl-C ends the recording"
                if hand is None
                else f"the scripted hand {hand} guides the arm"
            )
            demos = [record_demonstration(arm, the_task.name, duration, hand=scripted)]
            discarded: list[str] = []
        finally:
            arm.close()
    else:
        teacher = BlindTeacher(the_task, TeacherStyle(pattern=pattern), seed=seed, robot=robot)
        demos, discarded = teacher.record(count, progress=True)
    _store(out, demos, append, overwrite)
    console.print(
        f"recorded {len(demos)} demonstration(s) of [bold]{the_task.name}[/] -> {out}"
        + (f" (discarded {len(discarded)}: {'; '.join(discarded)})" if discarded else "")
    )


def _scripted_hand(
    hand: Path | None, real: bool, host: str | None, duration: float | None
) -> tuple[Guide, Callable[[Guide], None], str] | None:
    """``--hand``'s guide, read and checked before anything connects, with the function that
    hands it to the twin on ``host``; ``None`` without --hand."""
    if hand is None:
        return None
    from teachfit.robot.franka.hand import read_guide
    from teachfit.robot.franka.hand_channel import send_guide
    from teachfit.robot.franka.twin import check_host

    if not real or host is None:
        raise TeachfitError(
            f"--hand {hand}: a scripted hand guides the Franka twin only: give --robot franka "
            "--host 127.0.0.1 with teachfit robot twin running"
        )
    if duration is not None:
        raise TeachfitError(
            f"--hand {hand}: the guide sets the recording's length: drop --duration"
        )
    try:
        check_host(host)
    except TeachfitError:
        raise TeachfitError(
            f"--hand {hand}: --host {host} is not loopback: a scripted hand guides only the "
            "twin (teachfit robot twin); on a real arm a person guides it, drop --hand"
        ) from None
    guide = read_guide(hand)
    return guide, lambda g: send_guide(host, g, f"--hand {hand}"), str(hand)


def _check_target(out: Path, append: bool, overwrite: bool) -> None:
    """Refuse, before any work, an existing ``out`` that neither --append nor --overwrite names:
    ``demo record`` and ``demo import`` follow the same policy."""
    if append and overwrite:
        raise TeachfitError("give one of --append and --overwrite, not both")
    if out.is_dir():
        raise TeachfitError(f"--out {out} is a folder: give a file name such as {out / 'demos.h5'}")
    if out.exists() and not (append or overwrite):
        raise TeachfitError(
            f"{out} exists: pass --append to add to it or --overwrite to replace it"
        )
    if append:
        check_appendable(out)


def _store(out: Path, demos: list[Any], append: bool, overwrite: bool) -> None:
    """Write ``demos`` to ``out`` (atomically) by the --append/--overwrite policy."""
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise TeachfitError(f"--out {out}: cannot create its folder ({exc.strerror})") from exc
    if append:
        append_dataset(out, demos)
    else:
        write_dataset(out, demos, overwrite=overwrite)


def _option(flag: str, build: Callable[..., T], *args: Any) -> T:
    """``build(*args)``, its DatasetError reported against the command-line ``flag``."""
    try:
        return build(*args)
    except DatasetError as exc:
        option = {"force_off_n": "--force-off", "force_on_n": "--force-threshold"}.get(
            exc.column or "", flag
        )
        raise TeachfitError(f"{option}: {bare(exc)}") from exc


@app.command("import")
@guarded
# Long (> 60 lines) only by its options' declarations: the body checks, reads, imports, prints
def import_(
    log: Annotated[
        Path, typer.Argument(help="robot log: CSV, ROS 1 .bag, ROS 2 bag folder, .db3 or .mcap")
    ],
    task: Annotated[
        str | None,
        o.task("required: the task the log demonstrates (teachfit tasks, or a task .toml)"),
    ] = None,
    columns: Annotated[
        Path, typer.Option(help="CSV column map (TOML) to read the log with")
    ] = Path("columns.toml"),
    out: Annotated[Path, typer.Option(help="HDF5 file to write")] = Path("demos.h5"),
    append: o.Append = False,
    overwrite: o.Overwrite = False,
    name: Annotated[
        str | None, typer.Option(help="demonstration name (default: file stem)")
    ] = None,
    rate: Annotated[
        float | None, typer.Option(min=0, help="Hz, for a CSV log without a time column")
    ] = None,
    transform: Annotated[
        str | None,
        typer.Option(help="'first-pose' or 'FRAME:x,y,z,qw,qx,qy,qz' (log frame in FRAME)"),
    ] = None,
    pose_topic: Annotated[str | None, typer.Option(help="bag: pose topic")] = None,
    wrench_topic: Annotated[str | None, typer.Option(help="bag: wrench topic")] = None,
    wrench_sign: Annotated[
        int, typer.Option(help="bag: +1 environment-on-tool wrench, -1 robot-applied")
    ] = 1,
    child_frame: Annotated[str | None, typer.Option(help="bag: child frame of a tf topic")] = None,
    segment: Annotated[
        str | None, typer.Option(help="cut into demonstrations: window, contact or marker")
    ] = None,
    window: Annotated[float, typer.Option(min=0, help="--segment window: length (s)")] = 30.0,
    force_threshold: Annotated[
        float, typer.Option(min=0, help="--segment contact: force (N) that starts a contact phase")
    ] = 5.0,
    force_off: Annotated[
        float | None, typer.Option(help="--segment contact: force (N) that ends it (default half)")
    ] = None,
    min_duration: Annotated[float, typer.Option(min=0, help="shortest piece kept (s)")] = 1.0,
    marker_value: Annotated[
        str | None, typer.Option(help="--segment marker: keep runs with this value")
    ] = None,
    accept: Annotated[
        list[str] | None, typer.Option(help=f"accept a failed check: {', '.join(CHECKS)}")
    ] = None,
    accept_implausible: Annotated[bool, typer.Option(help="accept every failed check")] = False,
) -> None:
    """Import a real robot log (CSV or ROS bag) as demonstrations into --out (an existing file
    needs --append or --overwrite)."""
    task = _import_task(task, log)
    if out.is_dir():
        raise TeachfitError(f"--out {out} is a folder: give a file name such as {out / 'demos.h5'}")
    _not_an_input(out, log, columns)
    frame = None if transform is None else _option("--transform", FrameTransform.parse, transform)
    source = LogSource(columns, rate, pose_topic, wrench_topic, wrench_sign, child_frame)
    raw, frame = read_robot_log(log, source, frame)
    segmenter = None
    if segment is not None:
        cut = (segment, window, force_threshold, force_off, min_duration, marker_value)
        segmenter = _option("--segment", Segmenter, *cut)
    accepted = frozenset(accept or ()) | ({"all"} if accept_implausible else set())
    options = ImportOptions(transform=frame, accept=accepted, segmenter=segmenter)
    result = build_demos(raw, task=task, name=name or log.stem, options=options)
    for note in result.notes:
        console.print(f"[yellow]note:[/] {escape(note)}")
    _check_target(out, append, overwrite)
    _store(out, list(result.demos), append, overwrite)
    _print_import(result, log, out)


def _print_import(result: ImportResult, log: Path, out: Path) -> None:
    """The table of imported demonstrations and the closing line."""
    table = Table(
        title=f"{log} -> {out}", caption="start, duration: s; rate: Hz; extent: mm; |F|: N"
    )
    table.add_column("demonstration", no_wrap=True)
    for col in ("start", "duration", "samples", "rate", "x-y extent", "peak |F|"):
        table.add_column(col, justify="right", no_wrap=True)
    for piece in result.pieces:
        table.add_row(
            piece.name,
            f"{piece.start_s:.2f}",
            f"{piece.duration_s:.2f}",
            str(piece.samples),
            f"{piece.rate_hz:g}",
            f"{piece.extent_mm[0]:.1f} x {piece.extent_mm[1]:.1f}",
            "-" if piece.peak_force_n is None else f"{piece.peak_force_n:.1f}",
        )
    print_table(table)
    console.print(
        f"imported {len(result.demos)} demonstration(s) in frame {result.demos[0].frame!r} "
        f"from {log} -> {out}"
    )


def _import_task(task: str | None, log: Path) -> str:
    """The name of the task a log demonstrates: ``--task`` is required, a log does not say."""
    if task is None:
        raise TeachfitError(
            f"give --task: which task {log} demonstrates (one of {', '.join(sorted(TASKS))}, "
            "or a task .toml file); a real log does not say, and a demonstration of the wrong "
            "task is refused by search run and learn"
        )
    return load_task(task).name


def _not_an_input(out: Path, *inputs: Path) -> None:
    """Refuse an ``--out`` that is one of the command's inputs (or inside a bag folder): with
    --overwrite the log or its map would be replaced by the HDF5 file."""
    for given in inputs:
        inside = given.is_dir() and given.resolve() in out.resolve().parents
        if inside or (out.exists() and given.exists() and out.samefile(given)):
            raise TeachfitError(
                f"--out {out} is {'inside ' if inside else ''}the input {given}: give another "
                "file name, such as demos.h5"
            )


@app.command("export")
@guarded
def export(
    demo: Annotated[str, typer.Argument(help="demonstration FILE.h5:INDEX (FILE.h5: its first)")],
    out: Annotated[Path, typer.Option(help="CSV file to write")] = Path("demo.csv"),
    columns: Annotated[
        Path | None, typer.Option(help="CSV column map (TOML) to write that reads the CSV back")
    ] = None,
    overwrite: Annotated[bool, typer.Option(help="replace an existing file (CSV and map)")] = False,
) -> None:
    """Export one demonstration as a CSV log (s, m, w-x-y-z, N, N*m)."""
    check_output(columns, "columns")  # an output here (an input of demo import)
    the_demo = read_demo(demo)
    export_csv(the_demo, out, columns=columns, overwrite=overwrite)
    console.print(
        f"exported {the_demo.n_samples} samples of {the_demo.name or demo} "
        f"(frame {the_demo.frame!r}) -> {out}" + (f", map -> {columns}" if columns else "")
    )


@app.command("show")
@guarded
def show(
    dataset: Annotated[Path, typer.Argument(help="HDF5 demonstration file or run log (--log)")],
    plot: Annotated[Path | None, o.plot("paths over the hole, force over time")] = None,
) -> None:
    """List the demonstrations in a file (or a run log's episodes); optionally plot paths and
    wrenches (a run log: pose, wrench and active node over time)."""
    if is_run_log(dataset):
        show_run_log(dataset, plot)
        return
    rows = dataset_summary(dataset)
    table = Table(title=str(dataset))
    for col in ("index", "name", "task", "source", "samples", "duration", "rate"):
        table.add_column(col, justify="right" if col not in ("name", "task", "source") else "left")
    for r in rows:
        table.add_row(
            str(r["index"]),
            r["name"],
            r["task"],
            r["source"],
            str(r["samples"]),
            f"{r['duration']:.2f} s",
            f"{r['rate']:.0f} Hz",
        )
    print_table(table)
    if plot is not None:
        from teachfit.viz.figures import plot_demonstrations

        demos = read_dataset(dataset)
        tasks = {d.task for d in demos}
        try:
            task = load_task(tasks.pop()) if len(tasks) == 1 else None
        except TeachfitError:
            task = None
        plot_demonstrations(demos, plot, task)
        console.print(f"figure -> {plot}")
