"""Versioned TOML files of the capture pipeline (rig, markers): read checked, write plainly.

Each file starts with ``format = "<name>"`` and ``version = <n>``; reading checks both, and
every problem is one :class:`~teachfit.core.errors.CaptureError` naming the file.
"""

from __future__ import annotations

import tomllib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from teachfit.core.atomic import atomic_write_text
from teachfit.core.errors import CaptureError

__all__ = ["read_versioned_toml", "write_versioned_toml"]


def read_versioned_toml(path: str | Path, what: str, fmt: str, version: int) -> dict[str, Any]:
    """The parsed document of ``path``, a ``what`` file (e.g. ``"rig"``) of ``fmt``/``version``."""
    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise CaptureError(f"{what} file {path}: not a text (TOML) file ({exc.reason})") from exc
    except OSError as exc:
        raise CaptureError(f"{what} file {path}: cannot read ({exc.strerror or exc})") from exc
    except tomllib.TOMLDecodeError as exc:
        raise CaptureError(f"{what} file {path}: invalid TOML ({exc})") from exc
    if doc.get("format") != fmt or doc.get("version") != version:
        raise CaptureError(
            f"{what} file {path}: expected format = {fmt!r}, version = {version}, got "
            f"{doc.get('format')!r}, {doc.get('version')!r}"
        )
    return doc


def write_versioned_toml(path: str | Path, fmt: str, version: int, lines: Sequence[str]) -> Path:
    """Write ``format``, ``version`` and then ``lines`` (TOML written by hand: tomllib only
    reads) to ``path``, creating its folder."""
    path = Path(path)
    text = "\n".join([f'format = "{fmt}"', f"version = {version}", *lines])
    return atomic_write_text(path, text, f"{fmt} file")
