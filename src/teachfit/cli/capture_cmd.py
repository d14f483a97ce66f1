"""CLI of video capture: ``capture calibrate``, ``capture markers``, ``capture synth`` and
``bench capture`` (:func:`bench_capture_cmd`)."""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, TypedDict, Unpack

import numpy as np
import typer
from rich.table import Table

from teachfit.cli import options as o
from teachfit.cli.common import append_markdown, console, guarded
from teachfit.cli.progress import progress_bar
from teachfit.cli.tables import print_table
from teachfit.core.errors import CaptureError

if TYPE_CHECKING:
    from rich.progress import TaskID

    from teachfit.bench.capture import AccuracyRow, CaptureBench
    from teachfit.capture.synth import SynthConfig
    from teachfit.capture.track import Track
    from teachfit.demonstrations.dataset import Demonstration

__all__ = ["bench_capture_cmd", "capture_app"]

capture_app = typer.Typer(
    help="Demonstrations captured from video (multi-camera ArUco tracking).", no_args_is_help=True
)


def _pair(text: str, what: str) -> tuple[int, int]:
    try:
        a, b = (int(v) for v in text.lower().split("x"))
    except ValueError as exc:
        raise CaptureError(f"{what} must look like 1920x1080, got {text!r}") from exc
    return a, b


@capture_app.command("calibrate")
@guarded
def calibrate(
    charuco: Annotated[Path, typer.Option(help="folder with one sub-folder of images per camera")],
    out: Annotated[Path, typer.Option(help="rig TOML file to write")],
    squares: Annotated[str, typer.Option(help="board squares, columns x rows")] = "5x5",
    square: Annotated[float, typer.Option(help="square edge (m)")] = 0.04,
    marker: Annotated[float, typer.Option(help="marker edge (m)")] = 0.03,
    dictionary: Annotated[str, typer.Option(help="ArUco dictionary")] = "DICT_4X4_50",
) -> None:
    """ChArUco calibration: intrinsics per camera, extrinsics relative to the first camera."""
    from teachfit.capture.calibrate import CharucoSpec, calibrate_folder
    from teachfit.capture.rig import write_rig

    spec = CharucoSpec(_pair(squares, "--squares"), square, marker, dictionary)
    with console.status("calibrating"):
        rig, report = calibrate_folder(charuco, spec)
    table = Table(title="ChArUco calibration")
    for col in ("camera", "size", "fx, fy (px)", "images", "RMS px", "pair RMS px", "pair shots"):
        table.add_column(col)
    for cam in rig.cameras:
        table.add_row(
            cam.name,
            f"{cam.width}x{cam.height}",
            f"{cam.K[0, 0]:.1f}, {cam.K[1, 1]:.1f}",
            str(report.intrinsic_views[cam.name]),
            f"{report.intrinsic_rms[cam.name]:.3f}",
            f"{report.stereo_rms[cam.name]:.3f}" if cam.name in report.stereo_rms else "-",
            str(report.stereo_views.get(cam.name, "-")),
        )
    print_table(table)
    console.print(f"wrote {write_rig(rig, out)} (rig frame = camera {rig.cameras[0].name})")


@capture_app.command("markers")
@guarded
def markers(
    rig: Annotated[Path, typer.Option(help="rig TOML file")],
    markers: Annotated[Path, typer.Option(help="marker TOML file")],
    out: Annotated[Path, typer.Option(help="demonstration HDF5 file to write")],
    video: Annotated[
        list[Path] | None, typer.Option(help="video per rig camera, in rig order")
    ] = None,
    more_videos: Annotated[
        list[Path] | None, typer.Argument(help="more videos (--video a.mp4 b.mp4 c.mp4)")
    ] = None,
    camera: Annotated[
        list[int] | None, typer.Option(help="live camera index per rig camera")
    ] = None,
    frames: Annotated[int, typer.Option(min=1, help="live: stop after this many frames")] = 300,
    task: Annotated[str, o.task("the task the parts belong to: l-groove or tenon")] = "l-groove",
    plot: Annotated[Path | None, o.plot("the tracked pose over time")] = None,
    truth: Annotated[
        Path | None, typer.Option(help="ground truth HDF5 (capture synth) to score against")
    ] = None,
    no_filter: Annotated[bool, typer.Option("--no-filter", help="no temporal filter")] = False,
    overwrite: o.Overwrite = False,
) -> None:
    """Track the parts' markers in videos (or live cameras) and write the L2G demonstration."""
    from teachfit.capture.markers import read_markers
    from teachfit.capture.rig import read_rig
    from teachfit.capture.sources import CameraSet, VideoSet
    from teachfit.capture.track import TrackConfig, track_frames
    from teachfit.demonstrations.dataset import write_dataset

    videos = [*(video or []), *(more_videos or [])]
    if bool(videos) == bool(camera):
        raise CaptureError("give either --video files or --camera indices")
    the_rig, the_markers = read_rig(rig), read_markers(markers)
    source = (
        VideoSet(videos, the_rig) if videos else CameraSet(camera or [], the_rig, max_frames=frames)
    )
    cfg = TrackConfig(filter=None) if no_filter else TrackConfig()
    with progress_bar() as bar:
        job = bar.add_task("tracking", total=source.n_frames or None)
        track = track_frames(
            source, the_rig, the_markers, cfg, progress=lambda d: bar.update(job, completed=d)
        )
    name = "+".join(p.stem for p in videos) if videos else "live"
    demo = track.to_demonstration(task, name=f"{task}-capture-{name}")
    write_dataset(out, [demo], overwrite=overwrite)
    console.print(
        f"{track.n_frames} frames: {track.summary()}; median predicted error "
        f"{float(np.nanmedian(track.std_mm)):.3f} mm / {float(np.nanmedian(track.std_deg)):.3f} deg"
    )
    truth_demo = None if truth is None else _print_truth_errors(track, truth)
    console.print(f"wrote {out} ({demo.n_samples} poses of L in G)")
    if plot is not None:
        from teachfit.viz.capture_figures import track_figure

        console.print(f"wrote {track_figure(track, plot, truth_demo)}")


def _print_truth_errors(track: Track, truth: Path) -> Demonstration:
    """Print ``track``'s errors against the ground truth file ``truth``; return the truth."""
    from teachfit.bench.capture import pose_errors
    from teachfit.demonstrations.dataset import read_demo

    truth_demo = read_demo(truth)
    try:
        mm, deg = pose_errors(track, truth_demo)
    except ValueError as exc:
        raise CaptureError(f"truth {truth}: {exc}") from exc
    console.print(
        f"error vs truth: median {np.median(mm):.3f} mm (p95 {np.percentile(mm, 95):.3f}), "
        f"median {np.median(deg):.3f} deg (p95 {np.percentile(deg, 95):.3f})"
    )
    return truth_demo


class _SynthOptions(TypedDict, total=False):
    """The :class:`~teachfit.capture.synth.SynthConfig` fields the commands set."""

    distance: float
    noise: float
    blur: float
    lighting: float
    stride: int
    max_frames: int | None
    crf: int


def _synth_config(
    cameras: int, resolution: list[str] | None, **kw: Unpack[_SynthOptions]
) -> SynthConfig:
    from teachfit.capture.synth import SynthConfig

    res = [_pair(r, "--resolution") for r in (resolution or [])]
    default = SynthConfig().resolutions
    if not res:
        res = [default[i % len(default)] for i in range(cameras)]
    elif len(res) == 1:
        res = res * cameras
    if len(res) != cameras:
        raise CaptureError(f"{len(res)} resolutions for {cameras} cameras")
    return SynthConfig(resolutions=tuple(res), **kw)


@capture_app.command("synth")
@guarded
def synth(
    out: Annotated[Path, typer.Option(help="folder to write videos, rig, markers, truth into")],
    task: Annotated[str, o.task("l-groove or tenon")] = "l-groove",
    cameras: Annotated[int, typer.Option(min=1, max=3, help="number of cameras")] = 3,
    resolution: Annotated[
        list[str] | None, typer.Option(help="WxH, once for all or once per camera")
    ] = None,
    seed: Annotated[int, o.seed("the demonstration and the noise")] = 0,
    distance: Annotated[float, typer.Option(help="camera distance (m)")] = 0.6,
    noise: Annotated[float, typer.Option(help="pixel noise (grey levels)")] = 0.0,
    blur: Annotated[float, typer.Option(help="Gaussian blur (px)")] = 0.0,
    lighting: Annotated[float, typer.Option(help="light variation amplitude [0, 1)")] = 0.0,
    stride: Annotated[int, typer.Option(min=1, help="keep every n-th 30 Hz sample")] = 1,
    max_frames: Annotated[int | None, typer.Option(min=1, help="cap on the frame count")] = None,
    calib: Annotated[int, typer.Option(min=0, help="also render this many ChArUco shots")] = 0,
) -> None:
    """Render a scripted demonstration with marker-carrying parts: videos, rig, markers, truth."""
    from teachfit.capture.synth import write_synth_capture

    cfg = _synth_config(
        cameras,
        resolution,
        distance=distance,
        noise=noise,
        blur=blur,
        lighting=lighting,
        stride=stride,
        max_frames=max_frames,
    )
    with progress_bar() as bar:
        job = bar.add_task("rendering", total=None)
        paths = write_synth_capture(
            out,
            task=task,
            seed=seed,
            cfg=cfg,
            progress=lambda d, n: bar.update(job, completed=d, total=n),
        )
    if calib > 0:
        from teachfit.capture.calibrate import CharucoSpec
        from teachfit.capture.synth_calib import write_charuco_shots

        write_charuco_shots(out / "calib", CharucoSpec(), cfg, shots=calib, seed=seed)
        paths["calib"] = out / "calib"
    for key, path in paths.items():
        console.print(f"{key:8s} {path}")


def _filter_note(rows: Sequence[AccuracyRow], stride: int) -> None:
    """Say why the rows with and without the temporal filter agree, where they do."""
    from teachfit.capture.temporal import FilterConfig, adaptive_alpha

    with_f = [r for r in rows if r.filtered and r.cameras == rows[-1].cameras]
    without = [r for r in rows if not r.filtered]
    if not (with_f and without):
        return
    a, b = with_f[-1], without[-1]
    accel, dt = FilterConfig().accel or 0.0, stride / 30.0
    alpha = adaptive_alpha(accel, dt, 1e-3 * b.med_mm) if accel else float("nan")
    same = abs(a.med_mm - b.med_mm) < 5e-4 and abs(a.p95_mm - b.p95_mm) < 5e-4
    outliers = "none here: all frames valid" if a.valid == a.frames else "see 'valid'"
    console.print(
        f"temporal filter: {'no change at this precision' if same else 'see the rows above'}. "
        f"It weighs each frame by its predicted error: at {b.med_mm:.3f} mm, with hand "
        f"accelerations up to {accel:g} m/s² over {dt * 1e3:.0f} ms between frames, a frame "
        f"keeps alpha = {alpha:.4f} of its own pose, so the filter smooths only noisy frames "
        f"and rejects outliers beyond its 10 mm / 10° gate ({outliers})"
    )


def _print_accuracy(b: CaptureBench) -> None:
    """The accuracy rows of ``b`` as a table."""
    table = Table(title=f"Capture accuracy (L in G vs truth): {b.setup}")
    for col in ("cameras", "filter", "valid", "median mm", "p95 mm", "median deg", "p95 deg"):
        table.add_column(col, justify="right")
    for r in b.rows:
        table.add_row(
            str(r.cameras),
            "yes" if r.filtered else "no",
            f"{r.valid}/{r.frames}",
            f"{r.med_mm:.3f}",
            f"{r.p95_mm:.3f}",
            f"{r.med_deg:.3f}",
            f"{r.p95_deg:.3f}",
        )
    print_table(table)


@guarded
def bench_capture_cmd(
    stride: Annotated[int, typer.Option(min=1, help="keep every n-th 30 Hz sample")] = 2,
    noise: Annotated[float, typer.Option(help="pixel noise (grey levels)")] = 2.0,
    blur: Annotated[float, typer.Option(help="Gaussian blur (px)")] = 0.5,
    lighting: Annotated[float, typer.Option(help="light variation amplitude [0, 1)")] = 0.3,
    crf: Annotated[
        int, typer.Option(min=0, max=51, help="x264 quality of the videos (lower = better)")
    ] = 20,
    seed: Annotated[int, o.seed("the demonstration and the noise")] = 0,
    workdir: Annotated[Path | None, typer.Option(help="keep the rendered capture here")] = None,
    markdown: o.Markdown = None,
    write: o.WriteOld = False,
) -> None:
    """Capture accuracy (1, 2, 3 cameras) against ground truth, and fps per 1080p stream."""
    from teachfit.bench.capture import (
        TARGET_DEG,
        TARGET_FPS,
        TARGET_MM,
        run_capture_bench,
        to_markdown,
    )

    cfg = _synth_config(
        3, ["1920x1080"], noise=noise, blur=blur, lighting=lighting, stride=stride, crf=crf
    )
    with tempfile.TemporaryDirectory() as tmp, progress_bar() as bar:
        jobs: dict[str, TaskID] = {}

        def tick(label: str, done: int, total: int) -> None:
            if label not in jobs:
                jobs[label] = bar.add_task(label, total=total)
            bar.update(jobs[label], completed=done)

        b = run_capture_bench(workdir or tmp, cfg, seed=seed, progress=tick)
    _print_accuracy(b)
    _filter_note(b.rows, stride)
    three = [r for r in b.rows if r.filtered][-1] if b.rows[0].filtered else b.rows[-1]
    console.print(
        f"{three.cameras} cameras: median {three.med_mm:.3f} mm = {three.med_mm / TARGET_MM:.2f}x "
        f"target, {three.med_deg:.3f} deg = {three.med_deg / TARGET_DEG:.2f}x target (<= 1 is met)"
    )
    console.print(
        f"speed {b.stream}, one core: {b.fps:.1f} fps (decode {b.ms_decode:.1f} ms + track "
        f"{b.ms_track:.1f} ms per frame) = {b.fps / TARGET_FPS:.2f}x the "
        f"{TARGET_FPS:.0f} fps target"
    )
    markdown = markdown or (Path("BENCHMARKS.md") if write else None)
    if markdown is not None:
        console.print(f"markdown appended to {append_markdown(markdown, to_markdown(b))}")
