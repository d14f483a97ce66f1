import os
from pathlib import Path

import numpy as np
import pytest

from teachfit.core.errors import TeachfitError
from teachfit.demonstrations.dataset import Demonstration
from teachfit.execution.teacher import BlindTeacher, TeacherStyle
from teachfit.execution.teacher_cache import ENV, cache_key, cached
from teachfit.tasks import get_task


def _demo(shift: float) -> Demonstration:
    t = np.linspace(0.0, 1.0, 20)
    pos = np.column_stack([t * 0.01 + shift, np.zeros_like(t), np.full_like(t, 0.02)])
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (t.size, 1))
    return Demonstration(
        t, pos, quat, np.zeros((t.size, 6)), task="peg2d", source="simulated-teacher", meta={"k": 1}
    )


def test_a_recording_is_made_once_and_read_back(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv(ENV, str(tmp_path / "cache"))
    calls = []

    def record():
        calls.append(1)
        return [_demo(0.0), _demo(0.5)], ["never reached the hole"]

    first = cached("k1", record)
    again = cached("k1", record)
    assert len(calls) == 1
    assert again[1] == first[1] == ["never reached the hole"]
    assert [d.meta for d in again[0]] == [{"k": 1}, {"k": 1}]
    assert all(np.array_equal(a.pos, b.pos) for a, b in zip(first[0], again[0], strict=True))
    assert sorted(p.name for p in (tmp_path / "cache").iterdir()) == ["k1.h5", "k1.json"]
    # a damaged entry is recorded again, not trusted
    (tmp_path / "cache" / "k1.h5").write_bytes(b"not hdf5")
    cached("k1", record)
    assert len(calls) == 2
    # unset: nothing is stored
    monkeypatch.delenv(ENV)
    cached("k2", record)
    assert len(calls) == 3 and not (tmp_path / "cache" / "k2.h5").exists()


def test_the_key_follows_everything_a_recording_depends_on() -> None:
    task, style = get_task("peg2d"), TeacherStyle()
    base = dict(task=task, style=style, seed=1, robot="floating", n=1, limit=5)
    k = cache_key(**base)
    assert k == cache_key(**base)
    changed = [
        {"task": get_task("peg2d", clearance=0.0003)},
        {"style": TeacherStyle(speed=0.02)},
        {"seed": 2},
        {"robot": "fr3"},
        {"n": 2},
        {"limit": 6},
        {"kind": "socket"},
    ]
    assert len({cache_key(**{**base, **c}) for c in changed} | {k}) == len(changed) + 1


def test_a_teacher_replays_its_first_recording_from_the_run_cache() -> None:
    assert os.environ.get(ENV)  # tests/conftest.py: one cache per test run
    task = get_task("peg2d")
    first, _ = BlindTeacher(task, seed=1).record(1)  # the recording tests/execution share
    teacher = BlindTeacher(task, seed=1)
    again, _ = teacher.record(1)
    assert np.array_equal(first[0].pos, again[0].pos) and again[0].name == first[0].name
    # its random state did not advance as a recording's would: more from it is refused
    with pytest.raises(TeachfitError, match="new BlindTeacher"):
        teacher.demonstrate()
