"""The provenance header of every ``--markdown FILE`` block, and how a file splits into runs."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from typer.testing import CliRunner

from teachfit.cli import app
from teachfit.cli import provenance as pv
from teachfit.cli.common import append_markdown


def _p(**kw: str) -> pv.Provenance:
    base = {"command": "teachfit bench sim", "version": "0.1.0", "commit": "abc1234"}
    base |= {"date": "2026-12-04T18:50:02Z", "cpu": "AMD EPYC 7B13", "cores": "2", "load": "1.25"}
    return pv.Provenance(**(base | kw))


def test_a_header_reads_back_to_what_was_written() -> None:
    odd = "teachfit bench assembly --methods '' --plot 'a b.png' --x '-->' --y \"q\" & <"
    for p in (_p(), _p(command=odd, load=""), _p(source="transcribed", extra={"seen_in": "x"})):
        text = pv.header(p)
        first, visible = text.split("\n")
        assert first.startswith(pv.MARK) and first.endswith(" -->") and first.count("-->") == 1
        assert pv.parse_header(first) == p
        assert visible.startswith("*") and p.command in visible and "2 cores" in visible
    assert "transcribed" in pv.header(_p(source="transcribed")).split("\n")[1]
    with pytest.raises(ValueError, match="without commit"):
        pv.parse_header("<!-- teachfit-run command=x version=1 date=d cpu=c cores=2 source=s -->")


def test_one_run_writes_one_header_per_file_and_blocks_split_at_headers(tmp_path) -> None:
    a, b = tmp_path / "sub" / "a.md", tmp_path / "b.md"
    pv.new_run()
    for text in ("| a |\n|---|\n| 1 |", "table II\n"):
        append_markdown(a, text)
    append_markdown(b, "other")
    pv.new_run()
    append_markdown(a, "table I again")
    runs = pv.blocks("preamble\n" + a.read_text(encoding="utf-8"))
    assert len(runs) == 2 and len(pv.blocks(b.read_text(encoding="utf-8"))) == 1
    assert runs[0][1].endswith("| 1 |\n\ntable II") and "preamble" not in runs[0][1]
    assert runs[1][1].endswith("table I again") and "table II" not in runs[1][1]
    p = runs[-1][0]
    assert p.source == "command" and p.date.endswith("Z") and int(p.cores) >= 1 and p.cpu
    assert p.command == pv.command_line()


def test_a_script_s_command_line_is_what_was_typed(monkeypatch) -> None:
    monkeypatch.setattr("sys.argv", ["benchmarks/search_speed.py", "--sizes", "100,300", "a b"])
    assert pv.command_line() == "python benchmarks/search_speed.py --sizes 100,300 'a b'"
    monkeypatch.setattr("sys.argv", ["/venv/bin/teachfit", "bench", "sim"])
    assert pv.command_line() == "teachfit bench sim"


def _git(root: Path, *args: str) -> str:
    env = {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@x", "GIT_COMMITTER_NAME": "t",
           "GIT_COMMITTER_EMAIL": "t@x", "PATH": "/usr/bin:/bin"}  # fmt: skip
    out = subprocess.run(["git", "-C", str(root), *args], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


def test_the_commit_is_the_source_tree_s_and_says_when_it_is_modified(tmp_path) -> None:
    _git(tmp_path, "init", "-q")
    (tmp_path / "f.py").write_text("x = 1\n")
    _git(tmp_path, "add", "f.py")
    _git(tmp_path, "commit", "-qm", "c")
    sha = _git(tmp_path, "rev-parse", "--short", "HEAD")
    (tmp_path / "untracked.txt").write_text("not part of the tree\n")
    assert pv.source_commit(tmp_path) == sha
    (tmp_path / "f.py").write_text("x = 2\n")
    assert pv.source_commit(tmp_path) == sha + "+dirty"
    assert pv.source_commit(tmp_path / "nowhere") == "unknown"
    # only the code's own folder counts: a results file beside it changed leaves it clean
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "m.py").write_text("y = 1\n")
    _git(tmp_path, "add", "pkg/m.py")
    _git(tmp_path, "commit", "-qm", "pkg")
    sha = _git(tmp_path, "rev-parse", "--short", "HEAD")
    assert pv.source_commit(tmp_path / "pkg") == sha
    (tmp_path / "pkg" / "m.py").write_text("y = 2\n")
    assert pv.source_commit(tmp_path / "pkg") == sha + "+dirty"


def test_a_bench_command_heads_its_markdown(tmp_path) -> None:
    md = tmp_path / "planning.md"
    args = ["bench", "planning", "--tasks", "tenon", "--runs", "1", "--no-demo-runs", "0"]
    for _ in range(2):
        pv.new_run()  # each command its own process, as from a shell
        res = CliRunner().invoke(app, [*args, "--markdown", str(md)])
        assert res.exit_code == 0, res.output
    runs = pv.blocks(md.read_text(encoding="utf-8"))
    assert len(runs) == 2 and all("| tenon |" in body for _, body in runs)
