"""The README's "Python API" script runs as printed and prints an outcome."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def test_the_readme_python_script_records_learns_and_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    section = README.read_text().split("\n## Python API", 1)[1].split("\n## ", 1)[0]
    (script,) = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    monkeypatch.chdir(tmp_path)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(script, "README.md", "exec"), {"__name__": "readme"})  # noqa: S102
    outcome = out.getvalue().split()[0]
    from teachfit.core.outcome import Outcome

    assert outcome in {o.value for o in Outcome}
    assert (tmp_path / "api_demos.h5").is_file()
