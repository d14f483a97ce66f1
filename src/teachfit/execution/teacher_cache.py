"""A disk cache of the simulated teacher's recordings, for runs that repeat the same ones.

The seeded teacher is deterministic: the same task parameters, style, seed, robot, number of
demonstrations and teachfit version give the same recording. Benchmarks and test suites record
the same few demonstrations in many processes (each costs 10-20 s of simulation); with the
environment variable ``TEACHFIT_TEACHER_CACHE`` set to a folder, the first process stores
them there (HDF5, written atomically) and the others read them back. Unset, nothing is cached.
A cached entry is keyed by a SHA-256 of everything the recording depends on; a code change
to the teacher or the simulation that keeps the version number needs a fresh folder.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

from teachfit.core.atomic import atomic_write_text
from teachfit.core.errors import DatasetError
from teachfit.demonstrations.dataset import Demonstration, read_dataset, write_dataset

ENV = "TEACHFIT_TEACHER_CACHE"

if TYPE_CHECKING:
    from teachfit.execution.teacher_style import TeacherStyle

Recording = tuple[list[Demonstration], list[str]]


def cache_key(
    *,
    task: object,
    style: TeacherStyle,
    seed: int,
    robot: str,
    n: int,
    limit: int,
    kind: str = "record",
) -> str:
    """SHA-256 (hex) of what a recording depends on: ``task`` is the task, ``style`` its
    :class:`~teachfit.execution.teacher.TeacherStyle`, ``kind`` names the recording protocol
    (``"record"``: :meth:`BlindTeacher.record`; others: a caller's own starts)."""
    from teachfit import __version__

    params = getattr(task, "params", None)
    doc = {
        "version": __version__,
        "task": getattr(task, "name", type(task).__name__),
        "params": repr(params),
        "style": asdict(style),
        "seed": int(seed),
        "robot": robot,
        "n": int(n),
        "limit": int(limit),
        "kind": kind,
    }
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:32]


def cached(key: str, record: Callable[[], Recording]) -> Recording:
    """``record()``'s result, from the cache folder named by ``TEACHFIT_TEACHER_CACHE`` when
    it holds ``key`` (recorded and stored there otherwise); ``record()`` alone when unset."""
    folder = os.environ.get(ENV)
    if not folder:
        return record()
    root = Path(folder)
    data, notes = root / f"{key}.h5", root / f"{key}.json"
    if data.exists() and notes.exists():
        try:
            return read_dataset(data), list(json.loads(notes.read_text())["discarded"])
        except (OSError, ValueError, KeyError, DatasetError):
            pass  # a damaged entry is recorded again below
    demos, discarded = record()
    root.mkdir(parents=True, exist_ok=True)
    # the notes first: an entry counts only once its demonstrations are in place (os.replace)
    atomic_write_text(notes, json.dumps({"discarded": discarded}), "teacher cache entry")
    write_dataset(data, demos, overwrite=True)
    return demos, discarded
