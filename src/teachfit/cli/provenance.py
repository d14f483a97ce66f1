"""Where a benchmark result came from: the header of every block a ``--markdown FILE`` appends.

A command's first append to a file in one run (one process) starts with a provenance header:
one HTML comment that a script reads (``key=value``, values quoted as a POSIX shell would) and
one line a reader sees, e.g.::

    <!-- teachfit-run source=command command='teachfit bench sim' version=0.1.0 commit=1902191
    date=2026-12-04T18:50:02Z cpu='AMD EPYC' cores=2 load=2.03 -->
    *`teachfit bench sim` · teachfit 0.1.0, commit 1902191 · 2026-12-04 18:50 UTC · AMD EPYC,
    2 cores, load 2.0*

(each on one line). ``commit`` is the short git commit of the source tree teachfit runs from,
``+dirty`` when its tracked files differ from it, ``unknown`` outside a git checkout; ``date``
is UTC; ``load`` the 1-minute load average when the header is written. A block copied by hand
from an older record says ``source=transcribed`` (its figures were not written by the command;
the next real run replaces it) and may name the commit that recorded them (``recorded_in``).
:func:`blocks` splits a file into its headed blocks, oldest first.
"""

from __future__ import annotations

import datetime as _dt
import html
import os
import platform
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

__all__ = [
    "Provenance",
    "blocks",
    "command_line",
    "current",
    "first_in_run",
    "header",
    "new_run",
    "source_commit",
]

#: the machine-readable line's opening; :func:`blocks` splits a file at it
MARK = "<!-- teachfit-run "
_LINE = re.compile(r"^<!-- teachfit-run (.*) -->$", re.MULTILINE)
#: keys every header carries, in the order written
KEYS = ("source", "command", "version", "commit", "date", "cpu", "cores", "load")


@dataclass(frozen=True)
class Provenance:
    """One run's origin: the command line, teachfit's version and commit, the date (UTC, ISO
    8601) and the machine (CPU model, core count, 1-minute load average or ``""``)."""

    command: str
    version: str
    commit: str
    date: str
    cpu: str
    cores: str
    load: str = ""
    source: str = "command"
    extra: dict[str, str] = field(default_factory=dict)

    def values(self) -> dict[str, str]:
        """Every key of the header, in the order written (extra keys last)."""
        return {k: str(getattr(self, k)) for k in KEYS} | self.extra


#: files this process has headed (a ``teachfit`` command is one process, one run)
_HEADED: set[str] = set()


def first_in_run(path: Path) -> bool:
    """Whether this is the run's first append to ``path`` (then it is one no longer)."""
    key = str(Path(path).absolute())
    first = key not in _HEADED
    _HEADED.add(key)
    return first


def new_run() -> None:
    """Start a new run in this process: the next append to any file is headed again (for
    callers that run several commands in one process, such as tests)."""
    _HEADED.clear()


def command_line() -> str:
    """The command line as typed: ``teachfit ...``, a Python script run by its path (one in
    ``benchmarks/``) as ``python SCRIPT ...``; run otherwise (a test runner), the process's own
    arguments."""
    argv = sys.argv
    prog = Path(argv[0]) if argv else Path()
    if prog.name == "teachfit" or prog.parts[-2:] == ("teachfit", "__main__.py"):
        return shlex.join(["teachfit", *argv[1:]])
    if prog.suffix == ".py" and prog.name != "__main__.py":
        return shlex.join(["python", *argv])
    return shlex.join(argv)


def _git(root: Path, *args: str) -> str | None:
    try:
        out = subprocess.run(
            ["git", "-C", str(root), *args], capture_output=True, text=True, timeout=5, check=True
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip()


def source_commit(root: Path | None = None) -> str:
    """Short commit of the git checkout holding teachfit's source (``+dirty`` if a tracked file
    under ``root``, the package's own folder by default, is modified: a results file appended
    by an earlier run does not make the code dirty), or ``unknown`` (an installed wheel, no
    git)."""
    import teachfit

    root = root or Path(teachfit.__file__).resolve().parent
    sha = _git(root, "rev-parse", "--short", "HEAD")
    if not sha:
        return "unknown"
    status = _git(root, "status", "--porcelain", "--untracked-files=no", "--", ".")
    return sha + ("+dirty" if status else "")


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo`` on Linux), else what :mod:`platform` knows."""
    try:
        for line in Path("/proc/cpuinfo").read_text(errors="replace").splitlines():
            if line.startswith("model name") and ":" in line:
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def current(command: str | None = None) -> Provenance:
    """This run's provenance (the command line defaults to :func:`command_line`)."""
    import teachfit

    try:
        load = f"{os.getloadavg()[0]:.2f}"
    except OSError:
        load = ""
    now = _dt.datetime.now(_dt.UTC).replace(microsecond=0)
    return Provenance(
        command=command or command_line(),
        version=teachfit.__version__,
        commit=source_commit(),
        date=now.strftime("%Y-%m-%dT%H:%M:%SZ"),
        cpu=cpu_model(),
        cores=str(os.cpu_count() or "unknown"),
        load=load,
    )


def _short(load: str) -> str:
    try:
        return f"{float(load):.1f}"
    except ValueError:
        return load


def header(p: Provenance) -> str:
    """The two header lines (machine-readable comment, then the visible line), no newline."""
    pairs = " ".join(f"{k}={shlex.quote(v)}" for k, v in p.values().items() if v or k != "load")
    when = p.date.replace("T", " ")[:16] + " UTC" if "T" in p.date else p.date
    load = f", load {_short(p.load)}" if p.load else ""
    origin = ""
    if p.source == "transcribed":
        where = p.extra.get("recorded_in")
        of = f" of {where}" if where else ""
        origin = f"transcribed from the record{of}, not the command's output: "
    visible = (
        f"*{origin}`{p.command}` · teachfit {p.version}, commit {p.commit} · {when} · "
        f"CPU {p.cpu}, {p.cores} cores{load}*"
    )
    return f"{MARK}{html.escape(pairs, quote=False)} -->\n{visible}"


def parse_header(line: str) -> Provenance:
    """The :class:`Provenance` of a header's comment line (the inverse of :func:`header`)."""
    m = _LINE.match(line.strip())
    if m is None:
        raise ValueError(f"not a provenance line: {line[:80]!r}")
    pairs = dict(tok.split("=", 1) for tok in shlex.split(html.unescape(m.group(1))))
    missing = [k for k in KEYS if k not in pairs and k != "load"]
    if missing:
        raise ValueError(f"provenance line without {', '.join(missing)}: {line[:80]!r}")
    extra = {k: v for k, v in pairs.items() if k not in KEYS}
    return Provenance(**{k: pairs.get(k, "") for k in KEYS}, extra=extra)


def blocks(text: str) -> list[tuple[Provenance, str]]:
    """The headed blocks of a markdown file, oldest first: each header's provenance and the
    text after its comment line up to the next header (the visible line included). Text before
    the first header belongs to no run and is left out."""
    starts = [m.start() for m in _LINE.finditer(text)]
    out = []
    for i, start in enumerate(starts):
        end = starts[i + 1] if i + 1 < len(starts) else len(text)
        first, _, rest = text[start:end].partition("\n")
        out.append((parse_header(first), rest.strip("\n")))
    return out
