"""The README's tour, pasted as is (with small sizes), from a clean folder.

Every ``teachfit ...`` line of the ``## A tour`` section's bash blocks runs through the CLI in
a fresh temporary folder holding only ``examples/``, in the README's order; sizes are shrunk by
:data:`SMALL` so that the whole tour stays short. Commands whose work is rendering or a
benchmark are left to their own tests (:data:`ELSEWHERE`), but must still parse (``--help``).
"""

from __future__ import annotations

import re
import shlex
import shutil
from pathlib import Path

import pytest
from media_checks import read_video
from typer.testing import CliRunner

from teachfit.cli import app

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()

#: option -> the small value the test runs with
SMALL = {"--count": "1", "--starts": "1", "--points": "30", "--trials": "2", "--setups": "2"}
#: extra options per command (in-process trials: no worker start-up; small videos)
EXTRA = {
    ("learn", "skill"): ["--workers", "0"],
    ("assemble", "--task"): ["--fps", "5", "--width", "160", "--height", "120"],  # a small video
}
#: commands tested elsewhere (rendering, benchmarks, video capture and what depends on it)
ELSEWHERE = (
    ("bench",),
    ("render",),
    ("quickstart",),
    ("view",),
    ("capture",),
    ("plan",),
    ("search", "figures"),
    ("assemble", "--task", "l-groove"),  # its demonstration comes from the capture above
)


def tour_commands(readme: str) -> list[list[str]]:
    """The ``teachfit`` command lines of the README's tour, continuation lines joined."""
    section = readme.split("\n## A tour", 1)[1].split("\n## ", 1)[0]
    lines: list[list[str]] = []
    for block in re.findall(r"```bash\n(.*?)```", section, flags=re.S):
        for line in block.replace("\\\n", " ").splitlines():
            words = shlex.split(line, comments=True)
            if words and words[0] == "teachfit":
                lines.append(words[1:])
    return lines


def small(words: list[str]) -> list[str]:
    out = list(words)
    for i, word in enumerate(out[:-1]):
        if word in SMALL:
            out[i + 1] = SMALL[word]
    if "--render" in out and out[:2] == ["skill", "run"]:
        k = out.index("--render")
        del out[k : k + 2]  # rendering has its own test
    return out + EXTRA.get(tuple(out[:2]), [])  # type: ignore[arg-type]


COMMANDS = tour_commands((ROOT / "README.md").read_text())


def test_the_tour_has_commands_for_each_paper() -> None:
    names = {" ".join(w[:2]) for w in COMMANDS}
    assert {"demo record", "learn search", "search run", "learn skill", "skill run"} <= names
    assert not any("|" in w for words in COMMANDS for w in words)  # nothing pipes in a shell


def test_the_tour_runs_from_a_clean_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    ran = 0
    for words in COMMANDS:
        if any(tuple(words[: len(skip)]) == skip for skip in ELSEWHERE):
            path = [w for w in words if not w.startswith("-")][: len(words)]
            res = runner.invoke(app, [*path[:2], "--help"])
            assert res.exit_code == 0, (words, res.output)
            continue
        res = runner.invoke(app, small(words), env={"COLUMNS": "100"})
        assert res.exit_code == 0, (words, res.output)
        ran += 1
    assert ran >= 10
    # the tour's files: its own demonstrations, the imported log apart, the learned files
    from teachfit.demonstrations.dataset import read_dataset

    assert {d.source for d in read_dataset("demos.h5")} == {"simulated-teacher"}
    assert {d.source for d in read_dataset("log.h5")} == {"imported"}
    for name in ("peg.model", "demos.png", "plan.png", "skill.png", "puzzle.toml"):
        assert Path(name).stat().st_size > 0, name
    assert read_video(Path("trial.mp4")).shape[1:3] == (120, 160)  # assemble's --width/--height
