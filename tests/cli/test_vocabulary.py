"""One vocabulary over the whole command tree: one option name, one kind, one help."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.cli.options import CANONICAL

runner = CliRunner()

#: help text and output must not carry RST markup or the project's internal words
FORBIDDEN = (
    re.compile(r"``"),
    re.compile(r":(class|func|meth|mod|data):"),
    re.compile(r"\bseed [ABC]\b"),
    re.compile(r"issue's"),
    re.compile(r"\bsession \d"),
)


def _commands() -> Iterator[tuple[str, object]]:
    def walk(cmd: object, path: str) -> Iterator[tuple[str, object]]:
        subs = getattr(cmd, "commands", None)
        if subs:
            for name, sub in subs.items():
                yield from walk(sub, f"{path} {name}".strip())
        else:
            yield path, cmd

    yield from walk(typer.main.get_command(app), "")


def _kind(param: object) -> str:
    if getattr(param, "is_flag", False):
        return "flag"
    bare = str(param.type_descriptor.annotation).lower()  # type: ignore[attr-defined]
    for kind in ("int", "float", "path"):
        if kind in bare:
            return kind
    return "text"


COMMANDS = dict(_commands())
#: (command, option) whose help is known to differ from the canonical one, to align when that
#: command is next edited (its owner's call)
PENDING = {("tasks show", "--plot")}


def test_the_tree_is_walked() -> None:
    assert {"demo record", "search run", "learn search", "bench planning"} <= set(COMMANDS)


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_option_has_help_and_one_meaning(name: str) -> None:
    cmd = COMMANDS[name]
    assert cmd.help and cmd.help.strip(), f"{name}: no help"  # type: ignore[attr-defined]
    texts = [cmd.help]  # type: ignore[attr-defined]
    for param in cmd.params:  # type: ignore[attr-defined]
        if getattr(param, "hidden", False):
            assert "old spelling of" in (param.help or ""), f"{name} {param.opts}: hidden alias"
            continue
        assert param.help and param.help.strip(), f"{name} {param.name}: no help"
        texts.append(param.help)
        if param.param_type_name != "option":
            continue
        flag = next(o for o in param.opts if o.startswith("--"))
        assert not any(o.startswith("-") and not o.startswith("--") for o in param.opts), (
            f"{name} {flag}: short names are kept only as hidden old spellings"
        )
        if flag in CANONICAL and (name, flag) not in PENDING:
            kind, start = CANONICAL[flag]
            assert _kind(param) == kind, f"{name} {flag}: {_kind(param)}, canonical {kind}"
            assert param.help.startswith(start), f"{name} {flag}: help {param.help!r}"
    for text in texts:
        for pattern in FORBIDDEN:
            assert not pattern.search(text), f"{name}: {pattern.pattern!r} in {text!r}"


def test_shared_names_mean_one_thing() -> None:
    """An option that two commands take has one kind everywhere and is in :data:`CANONICAL`
    (where its help is pinned), unless each command's help is the same text."""
    seen: dict[str, set[tuple[str, str]]] = {}
    for cmd in COMMANDS.values():
        for param in cmd.params:  # type: ignore[attr-defined]
            if param.param_type_name == "option" and not param.hidden:
                flag = next(o for o in param.opts if o.startswith("--"))
                seen.setdefault(flag, set()).add((_kind(param), param.help))
    for flag, uses in seen.items():
        kinds = {k for k, _ in uses}
        assert len(kinds) == 1, f"{flag}: kinds {kinds}"
        if len(uses) > 1 and flag not in CANONICAL:
            starts = {h.split(" (")[0].split(":")[0] for _, h in uses}
            assert len(starts) == 1, f"{flag} is shared but not canonical: {sorted(uses)}"


def test_version_and_old_spellings() -> None:
    from importlib.metadata import version

    res = runner.invoke(app, ["--version"])
    assert res.exit_code == 0 and res.output.strip() == f"teachfit {version('teachfit')}"
    # hidden old spellings still parse: -n of search plan is --points
    res = runner.invoke(app, ["search", "plan", "--help"])
    assert "--points" in res.output and " -n " not in res.output


ROOT = Path(__file__).resolve().parents[2]
#: the project's prose beside the code: the results page, the changelog, the notes and results
PROSE = (
    ROOT / "BENCHMARKS.md",
    ROOT / "CHANGELOG.md",
    *sorted((ROOT / "docs").rglob("*.md")),
    *sorted((ROOT / "benchmarks" / "results").glob("*.md")),
)


def test_the_prose_speaks_of_the_project_not_of_work_sessions() -> None:
    word = re.compile(r"\bsession \d", re.IGNORECASE)
    assert len(PROSE) > 3
    hits = [
        f"{path.relative_to(ROOT)}:{n}"
        for path in PROSE
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if word.search(line)
    ]
    assert not hits, f"work sessions named in {hits}"


def test_the_code_names_the_papers_by_their_authors_and_no_work_sessions() -> None:
    """Docstrings, comments and tests say "Ehlers et al. 2019", not the jargon "seed A"."""
    jargon = re.compile(r"\b(seed [ABC]|seed_[abc])\b|\bsession \d", re.IGNORECASE)
    files = [*sorted((ROOT / "src").rglob("*.py")), *sorted((ROOT / "tests").rglob("*.py"))]
    files += [*sorted((ROOT / "benchmarks").glob("*.py")), ROOT / "README.md"]
    this = Path(__file__).resolve()
    hits = [
        f"{path.relative_to(ROOT)}:{n}"
        for path in files
        if path.resolve() != this
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if jargon.search(line)
    ]
    assert not hits, f"jargon in {hits}"
