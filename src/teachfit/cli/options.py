"""The command line's vocabulary: one option name, one kind and one help for one thing.

Every command declares the options below instead of spelling its own, so that ``--points`` is
TSHIX's sample count everywhere and ``--seed`` a seed value everywhere. ``tests/cli/
test_vocabulary.py`` walks the command tree and checks each option against :data:`CANONICAL`.

Old spellings stay accepted as *hidden* options (not in ``--help``), so that scripts keep
working: ``-n`` (now ``--points`` or ``--count``), ``--write`` (now ``--markdown FILE``),
``--benchmarks`` (``--markdown FILE``), ``--seeds``/``--no-demo-seeds`` of ``bench planning``
(now ``--runs``/``--no-demo-runs``), ``--demos`` of ``quickstart`` (``--count``), ``--out`` of
``render`` (``--render``), and the model file as the first argument of ``search plan`` and
``search figures`` (now ``--model``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer

from teachfit.core.errors import TeachfitError

T = TypeVar("T")

#: option name -> (kind, how its help starts); kinds: int, float, text, path, flag
CANONICAL: dict[str, tuple[str, str]] = {
    "--seed": ("int", "random seed"),
    "--points": ("int", "TSHIX points"),
    "--count": ("int", "number of demonstrations"),
    "--model": ("path", "search model"),
    "--render": ("path", "video (mp4)"),
    "--markdown": ("path", "append the results as markdown"),
    "--plot": ("path", "figure"),
    "--starts": ("int", "start poses"),
    "--task": ("text", "task"),
    "--tasks": ("text", "tasks"),
    "--demo": ("text", "demonstration"),
    "--out": ("path", ""),
    "--overwrite": ("flag", "replace an existing"),
    "--append": ("flag", "append to an existing file"),
    "--workers": ("int", "worker processes"),
    "--fps": ("int", "video frames per second"),
    "--width": ("int", "video width"),
    "--height": ("int", "video height"),
    "--robot": ("text", "robot to run on"),
    "--host": ("text", "address of a real robot"),
    "--realtime": ("flag", "real robot: require a real-time kernel"),
    "--reflex-force": ("float", "real robot: the collision reflex's force threshold"),
    "--controller": ("text", "controller"),
    "--trials": ("int", "trials"),
    "--method": ("text", ""),
    "--params": ("path", "skill parameters"),
    "--methods": ("text", "methods, comma-separated"),
    "--variants": ("int", "also run this many seeded task variants"),
    "--runs": ("int", "planning runs"),
    "--view": ("flag", "watch the run in MuJoCo's viewer"),
    "--skill": ("text", "skill: built-in name or skill .toml"),
    "--task-params": ("path", "task parameter overrides from a TOML file"),
}


@dataclass(frozen=True)
class Within:
    """The valid range of an integer option, as ``Annotated`` metadata beside its
    ``typer.Option``: :func:`teachfit.cli.common.guarded` refuses a value outside it in one line
    (exit 2), where typer's own ``min``/``max`` print a usage panel."""

    low: int
    high: int | None = None
    note: str = ""

    def check(self, flag: str, value: object) -> None:
        """Raise a :class:`TeachfitError` naming ``flag`` and the range if ``value`` is out."""
        if not isinstance(value, int) or (
            self.low <= value and (self.high is None or value <= self.high)
        ):
            return
        span = f">= {self.low}" if self.high is None else f"from {self.low} to {self.high}"
        note = f" ({self.note})" if self.note else ""
        raise TeachfitError(f"{flag} {value}: give an integer {span}{note}")


def old(flag: str, new: str) -> Any:
    """A hidden option ``flag``: an old spelling of ``new`` kept for scripts."""
    return typer.Option(flag, hidden=True, help=f"old spelling of {new}")


def pick(new: T, old_value: T | None) -> T:
    """The value of an option, or of its old spelling where that was given."""
    return new if old_value is None else old_value


def seed(what: str = "") -> Any:
    """``--seed N``: a seed *value* (a count of seeds is never called ``--seed(s)``)."""
    return typer.Option(
        "--seed", min=0, help="random seed" + (f" of {what}" if what else "") + " (an integer >= 0)"
    )


def plot(what: str) -> Any:
    """``--plot FILE``: a figure (PNG or PDF, by the file's suffix)."""
    return typer.Option("--plot", help=f"figure (PNG/PDF) to write: {what}")


def task(choices: str = "a built-in name (teachfit tasks) or a task .toml") -> Any:
    """``--task NAME``: the task a command works on."""
    return typer.Option("--task", help=f"task: {choices}")


def setups(what: str = "") -> Any:
    """``--setups N``: how many set-ups (taught hole pose and starts) drawn from the task's
    error distribution (:mod:`teachfit.execution.setups`)."""
    return typer.Option(
        "--setups",
        min=1,
        help="set-ups (taught hole pose with its error, and starts)" + (f" {what}" if what else ""),
    )


def starts(what: str = "") -> Any:
    """``--starts N``: how many start poses."""
    return typer.Option("--starts", min=1, help="start poses" + (f" {what}" if what else ""))


#: ``--task-param NAME=VALUE`` (repeatable): one task parameter override, SI units
TASK_PARAM = typer.Option("--task-param", help="task parameter override NAME=VALUE (SI units)")
TaskParams = Annotated[
    Path | None,
    typer.Option(
        "--task-params",
        help="task parameter overrides from a TOML file of NAME = VALUE lines (SI units; "
        "--task-param wins)",
    ),
]


def task_overrides(
    items: list[str] | None,
    error: type[Exception] = TeachfitError,
    path: Path | None = None,
) -> tuple[tuple[str, float], ...]:
    """``--task-params FILE`` then ``--task-param NAME=VALUE`` items as ``(name, value)``
    pairs, later names winning; ``error`` (one line) for a malformed item or file."""
    out: dict[str, float] = {}
    if path is not None:
        import tomllib

        try:
            table = tomllib.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
            raise error(f"{path}: cannot read the task parameters ({exc})") from None
        for name, value in table.items():
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise error(f"{path}: {name} must be a number (SI units), got {value!r}")
            out[name] = float(value)
    for item in items or []:
        name, sep, value = item.partition("=")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            sep = ""
        if not sep or not name.strip():
            raise error(f"--task-param wants NAME=VALUE with a number, got {item!r}")
    return tuple(out.items())


Seed = Annotated[int, seed()]
Points = Annotated[
    int, typer.Option("--points", min=1, help="TSHIX points sampled from the exploration density")
]
PointsOld = Annotated[int | None, old("-n", "--points")]
Count = Annotated[int, typer.Option("--count", min=1, help="number of demonstrations to record")]
CountOld = Annotated[int | None, old("-n", "--count")]
Model = Annotated[
    Path, typer.Option("--model", help="search model (JSON) written by 'teachfit learn search'")
]
ModelArgOld = Annotated[
    Path | None,
    typer.Argument(
        hidden=True, metavar="MODEL", help="old spelling of --model", show_default=False
    ),
]
Render = Annotated[Path | None, typer.Option("--render", help="video (mp4) to write")]
Markdown = Annotated[
    Path | None,
    typer.Option(
        "--markdown",
        help="append the results as markdown to this file, with where they came from "
        "(benchmarks/results/NAME.md feeds BENCHMARKS.md)",
    ),
]
WriteOld = Annotated[bool, old("--write", "--markdown benchmarks/results/NAME.md")]
Overwrite = Annotated[bool, typer.Option(help="replace an existing file")]
Append = Annotated[bool, typer.Option(help="append to an existing file")]
SuiteClearance = Annotated[
    float,
    typer.Option(
        help="diametral clearance (mm) of the parts suite's pegs in their holes: 0.2 by "
        "default (the simulated floor); e.g. 0.029, H7/g6's largest at 8 mm"
    ),
]
Workers = Annotated[
    int | None,
    typer.Option(help="worker processes (default: all cores; 0: in this process)"),
    Within(0, note="0: trials in this process"),
]
Fps = Annotated[int, typer.Option(min=1, max=240, help="video frames per second")]
Width = Annotated[int, typer.Option(min=16, max=7680, help="video width (px)")]
Height = Annotated[int, typer.Option(min=16, max=4320, help="video height (px)")]
View = Annotated[
    bool, typer.Option("--view", help="watch the run in MuJoCo's viewer (needs a display)")
]

__all__ = [
    "CANONICAL",
    "Append",
    "Count",
    "CountOld",
    "Fps",
    "Height",
    "Markdown",
    "Model",
    "ModelArgOld",
    "Overwrite",
    "Points",
    "PointsOld",
    "Render",
    "Seed",
    "TASK_PARAM",
    "TaskParams",
    "View",
    "Width",
    "Within",
    "Workers",
    "WriteOld",
    "old",
    "pick",
    "plot",
    "seed",
    "starts",
    "task",
    "task_overrides",
]
