"""Figures of whole assemblies: one execution's phases over time, and success against the
taught-hole error per method (Wilson 95 % intervals)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from teachfit.execution.engine import ExecutionResult  # noqa: E402
from teachfit.metrics.stats import SuccessSummary  # noqa: E402


def _save(fig: plt.Figure, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")  # written whole, then renamed
    fig.savefig(tmp, dpi=120)
    plt.close(fig)
    return tmp.replace(path)


def plot_phases(trace: ExecutionResult, path: str | Path, title: str = "") -> Path:
    """Which primitive was active when (coloured bands), the force on the tool (N) and the
    depth along the task frame's -z (mm; below the taught hole entry for peg tasks) over time
    (s since the start)."""
    log = trace.log
    fig, (ax0, ax1, ax2) = plt.subplots(
        3, 1, sharex=True, figsize=(8.0, 6.5), height_ratios=(1, 2, 2), constrained_layout=True
    )
    names = list(dict.fromkeys(v.node for v in trace.visits))
    colors = plt.get_cmap("tab10")
    for v in trace.visits:
        k = names.index(v.node)
        ax0.broken_barh(
            [(v.t_enter, max(v.t_exit - v.t_enter, 1e-3))], (k - 0.4, 0.8), color=colors(k)
        )
    ax0.set_yticks(range(len(names)), names, fontsize=8)
    ax0.invert_yaxis()
    ax0.set_ylabel("primitive")
    for i, lab in enumerate(("F_x", "F_y", "F_z")):
        ax1.plot(log.t, log.wrench[:, i], lw=0.9, label=lab)
    ax1.plot(log.t, np.linalg.norm(log.wrench[:, :3], axis=1), color="k", lw=0.8, label="|F|")
    ax1.set_ylabel("force on tool (N)")
    ax2.plot(log.t, log.depth * 1e3, color="tab:purple", lw=1.2)
    ax2.set_ylabel("depth along task -z (mm)")
    ax2.set_xlabel("time (s)")
    for ax in (ax0, ax1, ax2):
        for v in trace.visits:
            ax.axvline(v.t_enter, color="0.6", lw=0.6, ls=":")
        ax.grid(alpha=0.3)
    ax1.legend(fontsize=7, loc="upper left", ncols=4)
    outcome = "success" if trace.success else trace.outcome.value
    ax0.set_title(title or f"{trace.skill}: {outcome} after {trace.t_end:.2f} s", fontsize=9)
    return _save(fig, path)


#: legend labels of the benchmark's methods (other names are shown as they are)
_METHOD_LABELS = {
    "skill": "(a) skill alone",
    "search": "(b) learned search alone",
    "open-loop": "(c) plan, open loop",
    "joined": "(d) joined pipeline",
}


def plot_success_by_error(
    rows: Mapping[str, Sequence[tuple[float, SuccessSummary]]], path: str | Path, title: str = ""
) -> Path:
    """Success rate (with Wilson intervals) against the taught-hole error (mm), one line per
    method: ``rows[method] = [(error_m, summary), ...]``."""
    fig, ax = plt.subplots(figsize=(6.0, 4.0), constrained_layout=True)
    for j, (method, pts) in enumerate(rows.items()):
        e = np.array([p[0] for p in pts]) * 1e3 + 0.04 * (j - len(rows) / 2)
        rate = np.array([p[1].rate for p in pts])
        lo = np.clip(rate - np.array([p[1].low for p in pts]), 0.0, None)  # rounding
        hi = np.clip(np.array([p[1].high for p in pts]) - rate, 0.0, None)
        label = _METHOD_LABELS.get(method, method)
        ax.errorbar(e, rate, yerr=[lo, hi], marker="o", ms=4, capsize=3, lw=1.2, label=label)
    ax.set_xlabel("taught-hole error (mm)")
    ax.set_ylabel("success rate")
    ax.set_ylim(-0.05, 1.05)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, title="bars: Wilson 95 % interval", title_fontsize=7)
    ax.set_title(title, fontsize=9)
    return _save(fig, path)
