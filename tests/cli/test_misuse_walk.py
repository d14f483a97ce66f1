"""Walk every command of the CLI with missing, binary, truncated and wrong-type inputs and
out-of-range numbers: each ends with exit status 2 and one line naming the problem (typer's own
usage errors: its usage line and panel), no traceback, and no file left behind.

The commands are found by introspecting ``teachfit.cli.app``, so a new command is walked too.
Every bad input must be refused before any heavy work (the walk's own duration shows it; no
test here reads the clock).
"""

from __future__ import annotations

import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import typer
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.cli.common import OUTPUT_OPTIONS
from teachfit.demonstrations.dataset import Demonstration, write_dataset
from teachfit.demonstrations.export import export_csv

#: input files a str option or argument names, by parameter name: the suffix to try
FILE_STRS = {"task": ".toml", "xml": ".toml", "skill": ".toml", "demo": ".h5", "study": ".db"}
#: Path inputs by parameter name (others: .toml)
PATH_SUFFIX = {
    "demos": ".h5", "dataset": ".h5", "truth": ".h5", "log": ".csv", "model_file": ".model",
    "video": ".mp4", "more_videos": ".mp4",
}  # fmt: skip
#: enumerated str options: a value none of them takes
ENUMS = {
    "method", "controller", "robot", "covariance", "table", "protocol", "planner", "pattern",
    "segment", "components", "squares", "dictionary", "tasks", "methods", "scaling_workers",
}  # fmt: skip
#: output options named like another command's input
OUTPUTS_OF = {("demo", "export"): {"columns"}}
#: a missing file is a valid new one
NEW_OK = {"study"}
#: options a command needs although typer does not require them (it refuses their absence in
#: its own one line), given so that the walk reaches the command's other checks
NEEDED = {("demo", "import"): ["--task", "peg2d"]}
#: task TOML files with values of the wrong type
WRONG_TASKS = {
    "str": 'clearance = "abc"', "list": "clearance = [1, 2]", "bool": "clearance = true",
    "table": "[params]\nclearance = {a = 1}", "nan": "friction = nan", "frac": "n_sectors = 12.9",
}  # fmt: skip


def _commands(cmd: Any, path: tuple[str, ...] = ()) -> Iterator[tuple[tuple[str, ...], Any]]:
    if hasattr(cmd, "commands"):
        for name, sub in sorted(cmd.commands.items()):
            yield from _commands(sub, (*path, name))
    else:
        yield path, cmd


def _kind(param: Any) -> str:
    return str(param.type_descriptor.annotation).strip("'")


def _flag(param: Any) -> str:
    return max(param.opts, key=len)


def _demo() -> Demonstration:
    rng = np.random.default_rng(0)
    n = 60
    t = np.arange(n) * 0.02
    pos = np.column_stack([np.linspace(0.01, 0.0, n), np.zeros(n), np.full(n, 0.02)])
    xyzw = Rotation.from_rotvec(rng.normal(0.0, 0.01, (n, 3))).as_quat()
    return Demonstration(
        t=t, pos=pos, quat=xyzw[:, [3, 0, 1, 2]], wrench=np.zeros((n, 6)), task="peg2d",
        source="synthetic",
    )  # fmt: skip


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Bad (and a few good) input files in a folder ``in/``."""
    root = tmp_path_factory.mktemp("walk")
    d = root / "in"
    d.mkdir()
    junk = np.random.default_rng(1).integers(0, 256, 4096, dtype=np.uint8).tobytes()
    good_h5 = write_dataset(d / "good.h5", [_demo()])
    export_csv(_demo(), d / "good.csv", columns=d / "good_columns.toml")
    db = d / "good.db"
    with sqlite3.connect(db) as con:
        con.execute("create table t (x)")
    good = {
        ".h5": good_h5.read_bytes(),
        ".csv": (d / "good.csv").read_bytes(),
        ".toml": b'task = "peg2d"\nclearance = 0.0005\n',
        ".db": db.read_bytes(),
        ".model": b'{"task": "peg2d", "dims": ["x", "y"], "exploration": {"mean": [0.0',
        ".mp4": junk[:300],
    }
    for suffix, data in good.items():
        (d / f"binary{suffix}").write_bytes(junk)
        (d / f"truncated{suffix}").write_bytes(data[: max(len(data) // 2, 1)])
    (d / "truncated.toml").write_bytes(b'task = "peg2d"\nclearance = "0.00')
    for name, line in WRONG_TASKS.items():
        (d / f"wrong_{name}.toml").write_text(f'task = "peg2d"\n{line}\n')
    (d / "blocker").write_text("a file where a folder should be")
    return root


def _cases(path: tuple[str, ...], cmd: Any) -> Iterator[tuple[list[str], str]]:
    """``(argv, token)``: arguments with one bad input, and what the message must name."""
    outputs = OUTPUT_OPTIONS | OUTPUTS_OF.get(path, set())
    base: list[str] = []
    for p in cmd.params:
        if p.param_type_name == "argument" and p.required:
            name, kind = p.name, _kind(p)
            base.append(
                f"in/good.h5{':0' if 'str' in kind else ''}"
                if name in {"demos", "dataset", "demo"}
                else f"in/none{PATH_SUFFIX.get(name, '.toml')}"
            )
    for p in cmd.params:
        if p.param_type_name == "option" and p.required:
            base += [
                _flag(p),
                "o/out"
                if p.name in OUTPUT_OPTIONS
                else f"in/none{PATH_SUFFIX.get(p.name, '.toml')}",
            ]
    base += NEEDED.get(path, [])
    argpos = [p for p in cmd.params if p.param_type_name == "argument"]

    def with_value(p: Any, value: str) -> list[str]:
        if p.param_type_name == "argument":
            i = argpos.index(p)
            args = list(base)
            if i < len(args):
                args[i] = value
            else:
                args.append(value)
            return args
        args = [a for a in base]
        if _flag(p) in args:
            j = args.index(_flag(p))
            args[j + 1] = value
            return args
        return [*args, _flag(p), value]

    for p in cmd.params:
        kind = _kind(p)
        if p.name in ("install_completion", "show_completion") or "bool" in kind:
            continue
        if "Path" in kind and p.name in outputs:
            yield with_value(p, "in/blocker/out.png"), "blocker"
        elif "Path" in kind or (p.name in FILE_STRS and "str" in kind):
            suffix = FILE_STRS.get(p.name) or PATH_SUFFIX.get(p.name, ".toml")
            spec = ":0" if p.name == "demo" and suffix == ".h5" else ""
            for stem in (
                ("binary", "truncated") if p.name in NEW_OK else ("missing", "binary", "truncated")
            ):
                yield with_value(p, f"in/{stem}{suffix}{spec}"), f"{stem}{suffix}"
            if suffix == ".toml" and p.name == "task":
                for name in WRONG_TASKS:
                    yield with_value(p, f"in/wrong_{name}.toml"), f"wrong_{name}.toml"
        elif p.name in ENUMS:
            yield with_value(p, "bogus"), "bogus"
        elif "int" in kind or "float" in kind:
            yield with_value(p, "abc"), _flag(p)
            if p.min is not None:
                yield with_value(p, str(p.min - 1)), _flag(p)
            if p.max is not None:
                yield with_value(p, str(p.max + 1)), _flag(p)
            if "float" in kind:
                yield with_value(p, "nan"), _flag(p)


def _files(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*") if p.is_file()}


def test_every_command_refuses_bad_input_in_one_line(
    inputs: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(inputs)
    monkeypatch.setenv("COLUMNS", "80")
    before = _files(inputs)
    runner = CliRunner()
    root = typer.main.get_command(app)
    if hasattr(typer.testing, "_get_command"):  # build the command tree once, not per case
        monkeypatch.setattr(typer.testing, "_get_command", lambda _app: root)
    tried, failures = 0, []
    for path, cmd in _commands(root):
        # what an error line may name: the bad input, or (masking it) another given one
        named = [_flag(p) for p in cmd.params if p.param_type_name == "option"]
        named += [str(p.default) for p in cmd.params if isinstance(p.default, str | Path)]
        named += [n.split(":")[0] for n in named if ":" in n]  # demos.h5:0 -> demos.h5
        for argv, token in _cases(path, cmd):
            tried += 1
            res = runner.invoke(app, [*path, *argv])
            out = res.output.strip()
            lines = out.splitlines()
            typer_error = out.startswith("Usage:")
            problem = None
            if res.exit_code != 2:
                problem = f"exit {res.exit_code}"
            elif res.exception is not None and not isinstance(res.exception, SystemExit):
                problem = f"{type(res.exception).__name__}: {res.exception}"
            elif "Traceback" in out:
                problem = "traceback"
            elif not typer_error and (len(lines) != 1 or not lines[0].startswith("error:")):
                problem = f"{len(lines)} lines"
            elif not typer_error and not any(n in out for n in [token, *argv, *named]):
                problem = f"names neither {token!r} nor another input"
            if problem:
                failures.append(f"teachfit {' '.join([*path, *argv])}: {problem}\n  {out[-300:]}")
    left = sorted(_files(inputs) - before)
    print(f"CLI misuse walk: {tried} bad inputs tried, {tried - len(failures)} refused cleanly")
    assert tried > 300
    assert failures == [], f"{len(failures)} of {tried}:\n" + "\n".join(failures)
    assert left == [], f"files left behind: {left}"
