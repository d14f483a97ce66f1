"""A second misuse walk, for HDF5 inputs, file-size limits and file modes.

Every command that reads a demonstration file or a run log is given files crafted the way a
careless or hostile user could: groups and datasets swapped, wrong value types and shapes, huge
declared shapes in a small compressed file, links to other files (to a system file too), data
kept in another file, soft-link loops, attributes of the wrong type. Each must end with exit
status 2 and one line naming the file, no traceback, and nothing written (an ``--append``
target is left byte for byte). Writing under a file-size limit (``ulimit -f``, in a child
process) is one line naming the output, with the old file kept and no temporary left; outputs
follow the umask and an appended file keeps its mode.
"""

from __future__ import annotations

import os
import resource
import shutil
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import h5py
import numpy as np
import pytest
from run_logs import hand_made
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.core.atomic import TMP_MARK
from teachfit.demonstrations.dataset import Demonstration, write_dataset
from teachfit.demonstrations.export import export_csv
from teachfit.execution.recording import RunInfo, write_run_log

runner = CliRunner()
SRC = Path(__file__).resolve().parents[2] / "src"


def _demo(n: int = 60) -> Demonstration:
    t = np.arange(n) * 0.02
    pos = np.column_stack([np.linspace(0.01, 0.0, n), np.zeros(n), np.full(n, 0.02)])
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    return Demonstration(t, pos, quat, np.zeros((n, 6)), task="peg2d", source="synthetic")


def _put(name: str, value: object) -> Callable[[h5py.File], None]:
    """An edit putting ``value`` at ``name`` (a group for None), replacing what is there."""

    def edit(f: h5py.File) -> None:
        if name in f or isinstance(f.get(name, getlink=True), h5py.SoftLink):
            del f[name]
        if value is None:
            f.create_group(name)
        else:
            f[name] = value

    return edit


def _huge(name: str) -> Callable[[h5py.File], None]:
    """4e8 float64 values declared, gzip-compressed, in a file of a few KB."""

    def edit(f: h5py.File) -> None:
        del f[name]
        f.create_dataset(name, (400_000_000,), "f8", chunks=(1 << 20,), compression="gzip")

    return edit


def _attr(name: str, label: str, value: object) -> Callable[[h5py.File], None]:
    return lambda f: f[name].attrs.__setitem__(label, value)


def _stored_elsewhere(f: h5py.File) -> None:
    del f["demos/000/t"]
    f["demos/000"].create_dataset("t", (60,), "f8", external=[("/etc/hostname", 0, 480)])


#: crafted demonstration files: name -> edit of a good file
DEMO_FILES: dict[str, Callable[[h5py.File], None]] = {
    "demos_dataset": _put("demos", np.zeros(3)),
    "demo_dataset": _put("demos/000", np.zeros((60, 3))),
    "t_group": _put("demos/000/t", None),
    "t_text": _put("demos/000/t", np.array([b"0.0"] * 60)),
    "pos_complex": _put("demos/000/pos", np.zeros((60, 3), "c16")),
    "pos_compound": _put("demos/000/pos", np.zeros(60, [("x", "f8"), ("y", "f8")])),
    "pos_width": _put("demos/000/pos", np.zeros((60, 2))),
    "t_scalar": _put("demos/000/t", 1.0),
    "t_empty": _put("demos/000/t", h5py.Empty("f8")),
    "t_huge": _huge("demos/000/t"),
    "wrench_huge": _huge("demos/000/wrench"),
    "demos_external": _put("demos", h5py.ExternalLink("good.h5", "/demos")),
    "t_external_system": _put("demos/000/t", h5py.ExternalLink("/etc/hostname", "/t")),
    "t_stored_elsewhere": _stored_elsewhere,
    "t_soft_loop": _put("demos/000/t", h5py.SoftLink("/demos/000/t")),
    "t_soft_dangling": _put("demos/000/t", h5py.SoftLink("/nowhere")),
    "task_int": _attr("demos/000", "task", 7),
    "task_array": _attr("demos/000", "task", [b"peg2d", b"x"]),
    "name_float": _attr("demos/000", "name", 1.5),
    "meta_int": _attr("demos/000", "meta", 3),
    "format_int": _attr("/", "format", 7),
    "version_text": _attr("/", "format_version", "1"),
}
#: crafted run logs
RUN_LOGS: dict[str, Callable[[h5py.File], None]] = {
    "run_episodes_dataset": _put("episodes", np.zeros(3)),
    "run_episode_dataset": _put("episodes/000", np.zeros(3)),
    "run_visits_dataset": _put("episodes/000/visits", np.zeros(3)),
    "run_pos_huge": _huge("episodes/000/pos"),
    "run_pos_external": _put("episodes/000/pos", h5py.ExternalLink("/etc/x.h5", "/")),
    "run_node_text": _put("episodes/000/node", np.array([b"a"] * 5)),
    "run_outcome_int": _attr("episodes/000", "outcome", 7),
    "run_info_task_int": _attr("/", "info", '{"kind": "search", "task": 7}'),
    "run_info_list": _attr("/", "info", "[1]"),
}


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``in/``: a good demonstration file, CSV log and run log, and the crafted files."""
    root = tmp_path_factory.mktemp("hdf5walk")
    d = root / "in"
    d.mkdir()
    good = write_dataset(d / "good.h5", [_demo()])
    export_csv(_demo(), d / "good.csv", columns=d / "good_columns.toml")
    info = RunInfo("search", "peg2d", "floating", 0, "straight")
    run = write_run_log(d / "run.h5", [hand_made()], info)
    for files, source in ((DEMO_FILES, good), (RUN_LOGS, run)):
        for name, edit in files.items():
            shutil.copyfile(source, d / f"{name}.h5")
            with h5py.File(d / f"{name}.h5", "r+") as f:
                edit(f)
    return root


def _snapshot(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}


def _problem(res, names: str) -> str | None:
    """What is wrong with a refusal (None: exit 2, one ``error:`` line naming ``names``)."""
    out = res.output.strip()
    if res.exit_code != 2:
        return f"exit {res.exit_code}"
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        return f"{type(res.exception).__name__}: {res.exception}"
    if "Traceback" in out or len(out.splitlines()) != 1 or not out.startswith("error:"):
        return "not one error line"
    if names not in "".join(out.split()):
        return f"does not name {names}"
    return None


def _commands(name: str, kind: str) -> list[list[str]]:
    """The command lines that read ``in/NAME.h5`` (a copy ``o/NAME.h5`` is an append target)."""
    if kind == "run":
        return [["demo", "show", f"in/{name}.h5"]]
    csv = ["in/good.csv", "--columns", "in/good_columns.toml", "--task", "peg2d"]
    return [
        ["demo", "show", f"in/{name}.h5"],
        ["demo", "export", f"in/{name}.h5:0", "--out", "o/demo.csv"],
        ["learn", "search", f"in/{name}.h5", "--out", "o/m.model"],
        ["plan", "--demo", f"in/{name}.h5:0"],
        ["demo", "import", *csv, "--append", "--out", f"o/{name}.h5"],
        ["demo", "record", "--count", "1", "--seed", "1", "--append", "--out", f"o/{name}.h5"],
    ]


def test_crafted_hdf5_inputs_are_refused_in_one_line(root: Path, monkeypatch) -> None:
    monkeypatch.chdir(root)
    monkeypatch.setenv("COLUMNS", "80")
    (root / "o").mkdir()
    tried, failures = 0, []
    for files, kind in ((DEMO_FILES, "demo"), (RUN_LOGS, "run")):
        for name in files:
            shutil.copyfile(root / "in" / f"{name}.h5", root / "o" / f"{name}.h5")
            before = _snapshot(root)
            for argv in _commands(name, kind):
                tried += 1
                res = runner.invoke(app, argv)
                problem = _problem(res, f"{name}.h5")
                if problem is None and _snapshot(root) != before:
                    problem = "wrote or changed a file"
                if problem:
                    failures.append(f"teachfit {' '.join(argv)}: {problem}\n  {res.output[-300:]}")
    print(f"HDF5 misuse walk: {tried} crafted inputs, {tried - len(failures)} refused cleanly")
    assert tried >= 130
    assert failures == [], f"{len(failures)} of {tried}:\n" + "\n".join(failures)


def _limited(limit: int) -> Callable[[], None]:
    def apply() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, resource.RLIM_INFINITY))

    return apply


def _cli(args: list[str], cwd: Path, limit: int) -> subprocess.CompletedProcess[str]:
    """``teachfit ARGS`` in a child process whose files may not grow past ``limit`` bytes."""
    env = {**os.environ, "PYTHONPATH": str(SRC), "COLUMNS": "200"}
    code = "from teachfit.cli import main; main()"
    return subprocess.run(
        [sys.executable, "-c", code, *args], cwd=cwd, env=env, capture_output=True, text=True,
        preexec_fn=_limited(limit), timeout=300,
    )  # fmt: skip


def test_a_file_size_limit_is_one_line_naming_the_output(root: Path, tmp_path: Path) -> None:
    """``demo record`` (its recording read from the teacher cache the in-process run filled)
    and ``demo import --append`` under ``ulimit -f``: the old file is left as it was."""
    shutil.copytree(root / "in", tmp_path / "in")
    runner.invoke(
        app, ["demo", "record", "--count", "1", "--seed", "1", "--out", str(tmp_path / "warm.h5")]
    )
    old = (tmp_path / "in" / "good.h5").read_bytes()
    csv = ["in/good.csv", "--columns", "in/good_columns.toml", "--task", "peg2d"]
    cases = [
        (["demo", "record", "--count", "1", "--seed", "1", "--out", "o/rec.h5"], "o/rec.h5"),
        (["demo", "import", *csv, "--append", "--out", "in/good.h5"], "in/good.h5"),
    ]
    for args, out in cases:
        res = _cli(args, tmp_path, 4096)
        (line, *more) = res.stderr.strip().splitlines()
        assert res.returncode == 2 and more == [], res.stderr
        assert line.startswith("error: cannot write ") and line.endswith(
            f" {out}: the file-size limit was hit (File too large): raise it (ulimit -f) or "
            "write less"
        ), line
        assert not (tmp_path / out).exists() or out == "in/good.h5"
        assert not [p for p in tmp_path.rglob("*") if TMP_MARK in p.name]
    assert (tmp_path / "in" / "good.h5").read_bytes() == old


def test_outputs_follow_the_umask_and_an_append_keeps_the_mode(root: Path, tmp_path: Path) -> None:
    csv = [
        str(root / "in" / "good.csv"),
        "--columns",
        str(root / "in" / "good_columns.toml"),
        "--task",
        "peg2d",
    ]
    shared = tmp_path / "shared.h5"
    shutil.copyfile(root / "in" / "good.h5", shared)
    shared.chmod(0o640)
    old = os.umask(0o077)
    try:
        results = [
            runner.invoke(app, ["demo", "import", *csv, "--out", str(tmp_path / "new.h5")]),
            runner.invoke(app, ["demo", "import", *csv, "--append", "--out", str(shared)]),
            runner.invoke(
                app,
                ["demo", "record", "--count", "1", "--seed", "1", "--out", str(tmp_path / "r.h5")],
            ),
            runner.invoke(app, ["demo", "export", f"{shared}:1", "--out", str(tmp_path / "d.csv")]),
        ]
    finally:
        os.umask(old)
    assert [r.exit_code for r in results] == [0, 0, 0, 0], [r.output for r in results]
    modes = {p.name: p.stat().st_mode & 0o777 for p in tmp_path.iterdir()}
    assert modes == {"new.h5": 0o600, "shared.h5": 0o640, "r.h5": 0o600, "d.csv": 0o600}
