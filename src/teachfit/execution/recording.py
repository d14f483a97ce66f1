"""Run logs: what a ``search run``, ``skill run`` or assembly executed, one HDF5 file per run.

Every execution (episode) keeps the engine's whole :class:`~teachfit.execution.log.ExecutionLog`
(measured pose and wrench, commanded set-point and feed-forward, depth, active node) and its
:class:`~teachfit.execution.engine.ExecutionResult` summary; the file keeps what produced them.
:func:`read_run_log` gives the same values back, so a recorded run can be tabled and plotted as
if it had just been executed.

File layout (``format="teachfit-run"``, ``format_version=1``; world frame at the TCP)::

    /                        attrs: format, format_version, units (JSON), created (UTC, ISO 8601),
                                    teachfit (version), info (JSON: kind, task, robot, seed,
                                    method, command, options)
    /episodes/000            attrs: name, skill, outcome (Outcome value), reason, t_first_contact,
                                    t_end, time_to_success (s; NaN: none), path_length (m),
                                    peak_force (N), remaining (m), detected and
                                    ground_truth_inserted (1 yes, 0 no, -1 unknown), steps,
                                    wall_s, nodes (JSON: node names; ``node`` indexes them),
                                    primitives (JSON: node -> primitive), start (x y z qw qx qy
                                    qz; absent when not given)
    /episodes/000/t               (T,)   s since the episode started
    /episodes/000/pos, quat       (T, 3) m, (T, 4) w x y z: measured TCP pose
    /episodes/000/wrench          (T, 6) N, N*m exerted by the environment on the tool
    /episodes/000/setpoint_pos    (T, 3) m;  setpoint_quat (T, 4): the commanded set-point
    /episodes/000/wrench_ff       (T, 6) N, N*m: the commanded feed-forward wrench
    /episodes/000/depth           (T,)   m below the task frame's x-y plane
    /episodes/000/node            (T,)   int32, index into ``nodes`` of the active node (-1:
                                         the recovery node)
    /episodes/000/visits/{node, t_enter, t_exit, reason}   one row per stay in a node
    /episodes/000/planned/{t, pos, quat, wrench_ff}        the planned set-point trajectory
                                                           (searches; absent otherwise)
    /episodes/001 ...

Files are built in memory and written atomically (a temporary file beside the target, then
``os.replace``; the temporary file is removed when the write fails or is interrupted). Reading
refuses links to other files and checks kinds, types and declared sizes before reading
(:mod:`teachfit.core.h5file`). Read with :func:`read_run_log`;
:func:`is_run_log` tells a run log from a demonstration file.
"""

from __future__ import annotations

import json
import math
import shlex
import sys
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

import h5py
import numpy as np

from teachfit import __version__
from teachfit.core.errors import DatasetError, OutputError
from teachfit.core.h5file import H5Reader, one_line, open_hdf5, shown, write_hdf5
from teachfit.execution.engine import ExecutionResult
from teachfit.execution.episode import Episode
from teachfit.execution.recording_io import (
    FORMAT,
    FORMAT_VERSION,
    UNITS,
    is_run_log,
    read_episode,
    write_episode,
)
from teachfit.execution.skill_trial import SkillSetup, TrialOutcome
from teachfit.tasks.base import Task

if TYPE_CHECKING:
    from teachfit.execution.search import SearchRun


@dataclass(frozen=True)
class RunInfo:
    """What produced a run: ``kind`` (``"search"``, ``"skill"``, ``"assemble"``), task and robot
    names, seed, ``method`` (the search method or the skill and its controller), the process's
    ``command`` line, the command's parsed ``options`` (JSON values) and the task's nominal
    ``entry_height`` (m, world z of the hole entry; NaN: unknown)."""

    kind: str
    task: str
    robot: str
    seed: int
    method: str
    command: str = ""
    options: Mapping[str, Any] = field(default_factory=dict)
    entry_height: float = math.nan

    @classmethod
    def here(
        cls,
        kind: str,
        task: Task | str,
        robot: str,
        seed: int,
        method: str,
        options: Mapping[str, Any] | None = None,
    ) -> RunInfo:
        """A :class:`RunInfo` with this process's command line and ``options`` made JSON-safe
        (paths and other values as text); a :class:`Task` gives its name and entry height."""
        argv = [Path(sys.argv[0]).name, *sys.argv[1:]] if sys.argv else []
        safe = json.loads(json.dumps(dict(options or {}), default=str))
        name, entry = (task, math.nan) if isinstance(task, str) else (task.name, task.entry_height)
        return cls(kind, name, robot, int(seed), method, shlex.join(argv), safe, float(entry))


@dataclass(frozen=True)
class RunLog:
    """A run log read back: its :class:`RunInfo`, episodes, and when it was written."""

    info: RunInfo
    episodes: tuple[Episode, ...]
    created: str = ""
    version: str = ""

    @classmethod
    def of(
        cls,
        episodes: Iterable[Episode | ExecutionResult | SearchRun],
        info: RunInfo,
        path: str | Path = "run log",
    ) -> RunLog:
        """A run of episodes, engine results or search runs (``path`` names errors)."""
        return cls(info, tuple(_as_episode(e, i, Path(path)) for i, e in enumerate(episodes)))

    def depth(self, index: int) -> np.ndarray:
        """(T,) m of episode ``index``: the measured TCP below the task's nominal hole entry (as
        the success detector sees it), or, without an entry height, below the engine's task
        frame (``ExecutionLog.depth``)."""
        log = self.episodes[index].result.log
        if math.isfinite(self.info.entry_height):
            return self.info.entry_height - log.pos[:, 2]
        return log.depth


def skill_episodes(outcome: TrialOutcome, setup: SkillSetup) -> list[Episode]:
    """The episodes of one skill trial (one per start of ``setup``)."""
    return [
        Episode.of_skill(tr, setup.skill, st)
        for tr, st in zip(outcome.traces, setup.starts, strict=True)
    ]


def _as_episode(item: Episode | ExecutionResult | SearchRun, i: int, path: Path) -> Episode:
    """An :class:`Episode` from an episode, an engine result or a search run (its planned
    set-points kept)."""
    if isinstance(item, Episode):
        return item
    if isinstance(item, ExecutionResult):
        return Episode(item)
    from teachfit.execution.search import SearchRun  # planners and models: imported on use

    if isinstance(item, SearchRun):
        return Episode(item.result, planned=item.setpoints)
    raise DatasetError(
        f"episode {i} is a {type(item).__name__}, not an Episode, ExecutionResult or SearchRun",
        path=str(path),
    )


def check_run_log_target(path: str | Path) -> Path:
    """Refuse, before anything runs, a ``--log`` target that cannot take a run log: a folder,
    or an existing file that is not a run log (a demonstration file would be lost)."""
    path = Path(path)
    if path.is_dir():
        raise DatasetError(
            f"is a folder: give a file name such as {path / 'run.h5'}",
            path=str(path),
        )
    if path.exists() and not is_run_log(path):
        raise DatasetError(
            "exists and is not a run log (it would be replaced): choose another file name",
            path=str(path),
        )
    return path


def write_run_log(
    path: str | Path,
    episodes: Iterable[Episode | ExecutionResult | SearchRun],
    info: RunInfo,
) -> Path:
    """Write a run's episodes (:class:`Episode`, engine results or search runs) to ``path``
    atomically, replacing an older run log there; returns the path written.

    Raises
    ------
    DatasetError
        For a target refused by :func:`check_run_log_target`, an item that is not an episode, or
        a folder that cannot be created or written.
    """
    path = check_run_log_target(path)
    items = RunLog.of(episodes, info, path).episodes

    def fill(f: h5py.File) -> None:
        f.attrs["format"] = FORMAT
        f.attrs["format_version"] = FORMAT_VERSION
        f.attrs["units"] = json.dumps(UNITS)
        f.attrs["created"] = datetime.now(UTC).isoformat(timespec="seconds")
        f.attrs["teachfit"] = __version__
        f.attrs["info"] = json.dumps(asdict(info) | {"options": dict(info.options)})
        group = f.create_group("episodes")
        for i, ep in enumerate(items):
            write_episode(group.create_group(f"{i:03d}"), ep)

    try:
        write_hdf5(path, fill, "run log")
    except OutputError as exc:
        raise DatasetError(str(exc), path=str(path)) from exc
    return path


def read_run_log(path: str | Path) -> RunLog:
    """Read a run log written by :func:`write_run_log`.

    Raises
    ------
    DatasetError
        Naming the file, for a missing or non-HDF5 file, another format or version, or a
        missing dataset or attribute.
    """
    path = Path(path)
    if not is_run_log(path):
        what = "no such file" if not path.is_file() else "not a teachfit run log"
        raise DatasetError(what, path=str(path))
    with open_hdf5(path) as reader:
        f = reader.file
        reader.check_version(FORMAT_VERSION)
        info = _read_info(reader)
        group = reader.group(f, "episodes")
        try:
            keys = sorted(group, key=int)
            episodes = tuple(read_episode(reader, group, k) for k in keys)
        except (KeyError, TypeError, ValueError) as exc:
            raise DatasetError(
                f"incomplete or damaged run log ({one_line(exc)})", path=str(path)
            ) from exc
        created, version_text = (reader.text(f, k, "") for k in ("created", "teachfit"))
        return RunLog(info, episodes, created, version_text)


#: RunInfo's fields and the JSON types they take
INFO_TYPES: dict[str, type | tuple[type, ...]] = {
    "kind": str, "task": str, "robot": str, "seed": int, "method": str, "command": str,
    "options": dict, "entry_height": (int, float),
}  # fmt: skip


def _read_info(reader: H5Reader) -> RunInfo:
    """The run's :class:`RunInfo` from the root's ``info`` attribute (JSON), types checked."""
    try:
        raw = json.loads(reader.text(reader.file, "info"))
    except json.JSONDecodeError as exc:
        raise reader.error(f"attribute 'info' is not JSON ({exc})", "info") from exc
    if not isinstance(raw, dict):
        raise reader.error("attribute 'info' is not a run's description", "info")
    for key, value in raw.items():
        wrong = not isinstance(value, INFO_TYPES.get(key, object)) or isinstance(value, bool)
        if key in INFO_TYPES and wrong:
            raise reader.error(
                f"attribute 'info': {key} is {shown(value)}, not a "
                f"{getattr(INFO_TYPES[key], '__name__', 'number')}",
                "info",
            )
    try:
        return RunInfo(**raw)
    except TypeError as exc:
        raise reader.error(f"attribute 'info' is incomplete ({exc})", "info") from exc


def run_summary(run: RunLog) -> list[dict[str, Any]]:
    """One row per episode for a table: index, name, outcome, reason, duration (s), time to
    success (s, NaN: none), final depth (m, :meth:`RunLog.depth`), max force (N), nodes visited."""
    rows = []
    for i, ep in enumerate(run.episodes):
        r, depth = ep.result, run.depth(i)
        rows.append(
            {
                "index": i,
                "name": ep.name,
                "outcome": "success" if r.success else r.outcome.value,
                "reason": r.reason,
                "duration": r.t_end,
                "time_to_success": r.time_to_success,
                "final_depth": float(depth[-1]) if depth.size else math.nan,
                "max_force": r.peak_force,
                "nodes": " > ".join(v.node for v in r.visits),
            }
        )
    return rows
