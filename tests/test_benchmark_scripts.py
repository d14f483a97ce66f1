"""The scripts in ``benchmarks/`` append their tables with ``--markdown FILE`` as the ``teachfit
bench`` commands do: a provenance header naming the script's command line, then the table; a
path that cannot be written is refused before any work, in one line, exit status 2."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from types import ModuleType, SimpleNamespace

import pytest

from teachfit.cli import provenance as pv

ROOT = Path(__file__).resolve().parents[1]


def _script(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _run(monkeypatch, name: str, args: list[str]) -> None:
    """Run ``python benchmarks/NAME.py ARGS`` in this process, as one run."""
    pv.new_run()
    monkeypatch.setattr(sys, "argv", [f"benchmarks/{name}.py", *args])
    _script(name).main(args)


def _check(monkeypatch, capsys, tmp_path: Path, name: str, args: list[str]) -> str:
    """Run the script with ``--markdown``: one headed block naming its command line, returned;
    then refused paths (under a file, a folder): one line, exit 2, nothing run."""
    md = tmp_path / "out.md"
    _run(monkeypatch, name, [*args, "--markdown", str(md)])
    runs = pv.blocks(md.read_text(encoding="utf-8"))
    assert len(runs) == 1
    p, body = runs[0]
    assert p.source == "command" and p.commit and p.date.endswith("Z")
    assert p.command == f"python benchmarks/{name}.py " + " ".join([*args, "--markdown", str(md)])
    (tmp_path / "file.txt").write_text("x")
    capsys.readouterr()
    for bad in (tmp_path / "file.txt" / "out.md", tmp_path):
        with pytest.raises(SystemExit) as stop:
            _run(monkeypatch, name, [*args, "--markdown", str(bad)])
        out, err = capsys.readouterr()
        assert stop.value.code == 2 and out == ""
        assert err.startswith(f"error: --markdown {bad}: ") and err.count("\n") == 1
    return body


def test_search_speed_appends_the_family_table(monkeypatch, capsys, tmp_path) -> None:
    args = ["--part", "tsp", "--sizes", "12,16", "--instances", "1"]
    body = _check(monkeypatch, capsys, tmp_path, "search_speed", args)
    assert "**Open tour on three point families** (1 seeded instances" in body
    assert "| points | N = 12 | 16 |" in body
    for row in ("| uniform | 1.0", "| Gaussian | ", "| clustered (8 clusters) | ", "| LKH-3 CPU"):
        assert row in body
    with pytest.raises(SystemExit) as stop:  # --only-lkh makes no table to append
        _run(
            monkeypatch, "search_speed", [*args, "--only-lkh", "--markdown", str(tmp_path / "x.md")]
        )
    assert stop.value.code == 2 and "--only-lkh" in capsys.readouterr().err


def test_sensor_smoothness_appends_the_recordings(monkeypatch, capsys, tmp_path) -> None:
    args = ["--no-teacher", "--slide", "0.1"]
    body = _check(monkeypatch, capsys, tmp_path, "sensor_smoothness", args)
    assert "| recording | f_z std | lag-1 | goal met |" in body
    labels = ("floating", "fr3 (joint torques)", "fr3 (wrist F/T)")
    assert [line.split(" | ")[0] for line in body.splitlines() if " straight slide" in line] == [
        f"| {label}, 0.1 s straight slide" for label in labels
    ]


def test_feedforward_pairs_appends_one_row_per_n(monkeypatch, capsys, tmp_path) -> None:
    """The runs themselves are :func:`teachfit.bench.search.table2`'s (tested there): here
    made up, to check what the script writes from them."""
    from teachfit.bench import search

    def rate(successes: int, trials: int) -> SimpleNamespace:
        outcomes = (True,) * successes + (False,) * (trials - successes)  # paired by seed
        return SimpleNamespace(
            ours=SimpleNamespace(successes=successes, trials=trials), outcomes=outcomes
        )

    def table2(seed, sizes, n_traj, ablation, workers=None):
        (n,) = sizes
        return [rate(n // 100 + 1, n_traj)], [rate(n // 200, n_traj)]

    monkeypatch.setattr(search, "table2", table2)
    args = ["--robot", "floating", "--trajectories", "4", "--sizes", "100,300"]
    body = _check(monkeypatch, capsys, tmp_path, "feedforward_pairs", args)
    assert "**Feed-forward ablation on the floating, 4 paired trajectories per N**" in body
    assert (
        "| 100 | 2/4 = 50 % [15, 85] | 0/4 = 0 % [0, 49] | 2 : 0 (p = 0.5) | 6/20 = 30 % [15, 52] |"
        in body
    )
    assert (
        "| 300 | 4/4 = 100 % [51, 100] | 1/4 = 25 % [5, 70] | 3 : 0 (p = 0.25) | "
        "17/20 = 85 % [64, 95] | n/a |" in body
    )


def test_csv_import_speed_appends_both_readers(monkeypatch, capsys, tmp_path) -> None:
    body = _check(
        monkeypatch, capsys, tmp_path, "csv_import_speed", ["--rows", "50", "--repeats", "1"]
    )
    assert "**CSV import of 50 rows** (fastest of 1, seed 0)" in body
    assert "| `import_csv` | " in body and "| `numpy.loadtxt` (baseline) | " in body
    assert "| ratio import_csv / loadtxt | " in body


def test_search_speed_s_tshix_table_keeps_the_page_s_rows(monkeypatch) -> None:
    """All ten sizes are measured and printed; the markdown keeps the page's four rows (the
    timings themselves made up here: the real ones take a minute)."""
    ss = _script("search_speed")
    monkeypatch.setattr(ss, "_tshix_row", lambda p, dims, n, r, s: ([f"{len(dims)}", f"{n}"], n))
    monkeypatch.setattr(ss, "_ergodic_row", lambda dims, tr, ls, r: [f"{len(dims)}", f"{tr}"])
    tshix, ergodic = ss.tshix_speed(1, 0)
    assert [line for line in tshix.splitlines() if line[:3] in ("| 2", "| 3")] == [
        "| 2 | 100 |", "| 2 | 300 |", "| 2 | 500 |", "| 3 | 300 |"
    ]  # fmt: skip
    assert ergodic.splitlines()[-2:] == ["| 2 | 300 |", "| 3 | 300 |"]


def test_parts_clearance_appends_one_row_per_fit(monkeypatch, capsys, tmp_path) -> None:
    body = _check(
        monkeypatch, capsys, tmp_path, "parts_clearance", ["--parts", "round8-sharp-through"]
    )
    rows = [line for line in body.splitlines() if line.startswith("| round8")]
    assert [r.split(" | ")[1] for r in rows] == [
        "H7/g6 smallest (5 um)", "H7/g6 largest (29 um)", "suite (200 um)"
    ]  # fmt: skip
    assert all(r.split(" | ")[2] in ("2.5 um", "14.5 um", "100.0 um") for r in rows)


def test_exec_per_cpu_runs_and_compares_fixed_executions(monkeypatch, capsys, tmp_path) -> None:
    """One puzzle execution, run twice (the repeats must agree), written; compared with itself:
    ratio 1.00 and no differing fingerprint; a changed fingerprint is named, other parameter
    sets are refused in one line (exit 2)."""
    run = tmp_path / "run.json"
    _run(monkeypatch, "exec_per_cpu", ["--label", "here", "--out", str(run), "--tasks", "puzzle",
                                       "--executions", "1", "--repeats", "2"])  # fmt: skip
    data = json.loads(run.read_text(encoding="utf-8"))
    (fp,) = data["tasks"]["puzzle"]["fingerprints"]
    assert set(fp) == {"outcome", "success_tick", "ticks", "pos_um"} and fp["ticks"] > 0
    body = _check(monkeypatch, capsys, tmp_path, "exec_per_cpu", ["--compare", str(run), str(run)])
    assert "**Executions per CPU-second, here vs here**" in body
    last = body.splitlines()[-1]
    assert last.startswith("| all | 1 | ") and last.endswith(" | 1.00 | 0 |")
    moved = json.loads(run.read_text(encoding="utf-8"))
    moved["tasks"]["puzzle"]["fingerprints"][0]["pos_um"][2] += 3
    other = tmp_path / "other.json"
    other.write_text(json.dumps(moved), encoding="utf-8")
    capsys.readouterr()
    _run(monkeypatch, "exec_per_cpu", ["--compare", str(run), str(other)])
    out = capsys.readouterr().out
    assert "| puzzle | 1 | " in out and out.rstrip().endswith("(final position 3 µm apart)")
    moved["tasks"]["puzzle"]["params"][0]["force"] = -1.0
    other.write_text(json.dumps(moved), encoding="utf-8")
    with pytest.raises(SystemExit) as stop:
        _run(monkeypatch, "exec_per_cpu", ["--compare", str(run), str(other)])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.count("\n") == 1 and "other parameter sets" in err


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["--trials", "0"], "error: --trials 0: give at least 1"),
        (["--cases", "peg,nope"], "error: --cases peg,nope: known cases are peg, tshix-peg2d"),
    ],
)
def test_twin_vs_fr3_refuses_bad_input_before_starting_anything(
    monkeypatch, capsys, args: list[str], said: str
) -> None:
    with pytest.raises(SystemExit) as stop:
        _run(monkeypatch, "twin_vs_fr3", args)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and said in err and err.count("\n") == 1, err


def test_twin_vs_fr3_puts_the_fr3_side_where_the_twin_arm_stands() -> None:
    """``--fr3-cell twin`` gives the fr3 robot the twin cell's base and part mount (the two
    sides then differ in the protocol path only); ``own`` leaves the fr3 robot's defaults."""
    import dataclasses

    from teachfit.robot.fr3 import FR3Params
    from teachfit.robot.franka.twin_cell import TwinParams, cell_params

    script = _script("twin_vs_fr3")
    script.FR3_CELL[0] = "twin"
    opts = script.fr3_cell()
    cell = cell_params(TwinParams())
    placed = dataclasses.replace(FR3Params(), **opts)
    assert placed.base_pos == cell.base_pos and placed.mount_offset == cell.mount_offset
    assert placed.base_pos != FR3Params().base_pos  # the twin's base is not the fr3 robot's
    script.FR3_CELL[0] = "own"
    assert script.fr3_cell() == {}
