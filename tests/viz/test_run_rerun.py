"""Run logs as Rerun recordings: entities per episode, and a clear error without the SDK."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from run_logs import real_run

from teachfit.core.errors import TeachfitError
from teachfit.viz.run_rerun import require_rerun, write_rrd


def test_rrd_holds_each_episode(tmp_path: Path) -> None:
    pytest.importorskip("rerun", reason="the optional extra teachfit[rerun] is not installed")
    from rerun.chunk import RrdReader

    episodes, info = real_run()
    path = write_rrd(tmp_path / "run.rrd", episodes, info)
    assert not list(tmp_path.glob(".*.tmp"))
    rows: dict[str, int] = {}
    for chunk in RrdReader(path).stream():  # rows on the timeline (static ones: 0)
        n = 0 if chunk.is_static else chunk.num_rows
        rows[chunk.entity_path] = rows.get(chunk.entity_path, 0) + n
    for i, ep in enumerate(episodes):
        base = f"/episodes/{i:03d}"
        assert rows[f"{base}/force"] == rows[f"{base}/depth"] == ep.result.log.n_samples
        assert rows[f"{base}/tcp"] == 2 * ep.result.log.n_samples  # a point and a frame
        assert rows[f"{base}/events"] == len(ep.result.visits)
        assert f"{base}/planned" in rows and f"{base}/summary" in rows
    assert "/run" in rows


def test_missing_sdk_names_the_extra(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "rerun", None)  # import rerun -> ImportError
    with pytest.raises(TeachfitError, match=r"pip install 'teachfit\[rerun\]'"):
        require_rerun()
    episodes, info = real_run()
    with pytest.raises(TeachfitError, match="Rerun SDK"):
        write_rrd(tmp_path / "run.rrd", episodes, info)
    assert list(tmp_path.iterdir()) == []
