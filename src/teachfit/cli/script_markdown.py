"""``--markdown FILE`` for the scripts in ``benchmarks/`` (argparse, not typer): the same check
before any work and the same headed append as the ``teachfit bench`` commands'
(:func:`~teachfit.cli.common.check_output`, :func:`~teachfit.cli.common.append_markdown`,
:mod:`teachfit.cli.provenance`), a refused path reported as one line with exit status 2."""

from __future__ import annotations

import argparse
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from teachfit.cli.common import append_markdown, check_output
from teachfit.core.errors import OutputError, TeachfitError

__all__ = ["add_markdown_option", "append_table", "checked_markdown", "table"]


def table(title: str, header: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    """A markdown table under a title line: ``title``, a blank line, the header, the rows."""
    lines = [
        title,
        "",
        "| " + " | ".join(header) + " |",
        "| " + " | ".join("---" for _ in header) + " |",
    ]
    return "\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows])


def add_markdown_option(ap: argparse.ArgumentParser) -> None:
    """Give the script ``--markdown FILE`` (the help the commands' option has)."""
    ap.add_argument(
        "--markdown",
        type=Path,
        metavar="FILE",
        help="append the results as markdown to this file, with where they came from "
        "(benchmarks/results/NAME.md feeds BENCHMARKS.md)",
    )


@contextmanager
def _one_line(ap: argparse.ArgumentParser) -> Iterator[None]:
    """A :class:`TeachfitError` inside: ``error: MESSAGE`` on stderr and exit status 2."""
    try:
        yield
    except TeachfitError as exc:
        ap.exit(2, f"error: {exc}\n")


def checked_markdown(ap: argparse.ArgumentParser, path: Path | None) -> Path | None:
    """``path`` if a markdown file can be written there, checked before the script's work: its
    nearest existing folder writable (:func:`~teachfit.cli.common.check_output`) and the path
    itself not a folder; else one line and exit status 2."""
    with _one_line(ap):
        check_output(path, "markdown")
        if path is not None and path.is_dir():
            raise OutputError(f"--markdown {path}: it is a folder; give a file name")
    return path


def append_table(ap: argparse.ArgumentParser, path: Path | None, text: str) -> None:
    """Append ``text`` to ``path`` (nothing when ``None``) with the run's provenance header
    (:func:`~teachfit.cli.common.append_markdown`); a failed write is one line, exit 2."""
    if path is None:
        return
    with _one_line(ap):
        print(f"markdown appended to {append_markdown(path, text)}")
