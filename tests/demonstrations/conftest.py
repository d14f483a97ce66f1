"""Fixtures of the demonstrations tests: generated Panda-like logs in ``tmp_path``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from panda_logs import panda_log, write_log, write_map


@pytest.fixture
def make_log(tmp_path: Path) -> Callable[..., tuple[Path, Path]]:
    """Factory: ``make_log(kind, log_options, map_options)`` -> (csv path, map path)."""

    def make(kind: str = "search", log: dict | None = None, cmap: dict | None = None):
        csv = write_log(tmp_path / f"{kind}.csv", panda_log(kind), **(log or {}))
        return csv, write_map(tmp_path / f"{kind}.toml", **(cmap or {}))

    return make
