"""Figures of skill learning (Johannsmeier et al. 2019, Fig. 6): learning curves, parameter traces,
and the best execution's force and pose over time.

matplotlib with the Agg backend; every function writes ``path`` (png/pdf/svg by suffix) and
returns it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from teachfit.core.geometry import rz_from_quat, wxyz_to_rotation  # noqa: E402
from teachfit.core.params import ParamSpace  # noqa: E402
from teachfit.execution.engine import ExecutionResult  # noqa: E402
from teachfit.learning.curves import Band, best_so_far  # noqa: E402
from teachfit.learning.study import TrialRecord  # noqa: E402
from teachfit.viz.output import save_figure


def _save(fig: plt.Figure, path: str | Path) -> Path:
    return save_figure(fig, path)


def plot_learning_curves(
    bands: Mapping[tuple[str, str], Band], path: str | Path, title: str = ""
) -> Path:
    """Fig. 6: best-so-far cost vs trial, mean and 95 % band over experiments; one row per
    task, one column per method (``bands[(task, method)]``)."""
    tasks = list(dict.fromkeys(t for t, _ in bands))
    methods = list(dict.fromkeys(m for _, m in bands))
    fig, axes = plt.subplots(
        len(tasks),
        len(methods),
        squeeze=False,
        sharex=True,
        figsize=(3.2 * len(methods), 2.6 * len(tasks)),
        constrained_layout=True,
    )
    for i, task in enumerate(tasks):
        row = [b for (t, _), b in bands.items() if t == task]
        # one scale per task; a wide early band (failed first trials) may leave the frame
        top = min(
            max(float(np.nanmax(b.high)) for b in row),
            1.5 * max(float(np.nanmax(b.mean)) for b in row),
        )
        low = min(float(np.nanmin(b.low)) for b in row)
        for j, method in enumerate(methods):
            ax = axes[i, j]
            b = bands.get((task, method))
            if b is None:
                ax.set_axis_off()
                continue
            ax.fill_between(
                b.trials,
                b.low,
                b.high,
                color="0.75",
                lw=0,
                step="post",
                label="95 % CI" if b.n > 1 else None,
            )
            ax.step(
                b.trials, b.mean, where="post", color="tab:blue", lw=1.6, label=f"mean of {b.n}"
            )
            ax.set_ylim(max(0.0, low * 0.9), top * 1.05 + 1e-9)
            ax.grid(alpha=0.3)
            if i == 0:
                ax.set_title(method.upper() if len(method) <= 5 else method)
            if j == 0:
                ax.set_ylabel(f"{task}\nbest cost so far (s)")
            if i == len(tasks) - 1:
                ax.set_xlabel("trial")
            if i == 0 and j == 0:
                ax.legend(fontsize=7)
    if title:
        fig.suptitle(title, fontsize=10)
    return _save(fig, path)


def plot_study_curve(records: Sequence[TrialRecord], path: str | Path, title: str = "") -> Path:
    """One study: every trial's cost (failed ones in red) and the best cost so far."""
    costs = np.array([r.cost for r in records])
    ok = np.array([r.feasible for r in records])
    k = np.arange(1, costs.size + 1)
    fig, ax = plt.subplots(figsize=(6.4, 3.6), constrained_layout=True)
    ax.scatter(k[ok], costs[ok], s=12, color="tab:blue", label="feasible trial")
    ax.scatter(k[~ok], costs[~ok], s=12, color="tab:red", marker="x", label="failed trial")
    ax.step(k, best_so_far(costs), where="post", color="k", lw=1.5, label="best so far")
    ax.set_xlabel("trial")
    ax.set_ylabel("cost (s)")
    ax.set_yscale("log")
    # label the minor decades too: costs span 0.2-10 s, one "10^0" tick says nothing
    ax.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax.yaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=9)
    return _save(fig, path)


def plot_param_traces(
    records: Sequence[TrialRecord],
    space: ParamSpace,
    path: str | Path,
    title: str = "",
    units: Mapping[str, str] | None = None,
) -> Path:
    """Each learned parameter vs trial, unit-scaled to its domain (0 = low, 1 = high);
    feasible trials blue, failed red, the best trial's values as a dashed line. ``units``
    (name -> unit) labels each panel's domain."""
    from matplotlib.lines import Line2D

    names = space.names
    ncol = 4
    nrow = int(np.ceil(len(names) / ncol))
    fig, axes = plt.subplots(
        nrow,
        ncol,
        squeeze=False,
        sharex=True,
        sharey=True,
        figsize=(3.0 * ncol, 2.1 * nrow),
        constrained_layout=True,
    )
    k = np.arange(1, len(records) + 1)
    scaled = np.array([space.to_unit(r.params) for r in records]).reshape(len(records), -1)
    ok = np.array([r.feasible for r in records], dtype=bool)
    best = min((r for r in records if r.feasible), key=lambda r: r.cost, default=None)
    for idx, ax in enumerate(axes.flat):
        if idx >= len(names):
            ax.set_axis_off()
            continue
        ax.scatter(k[ok], scaled[ok, idx], s=6, color="tab:blue")
        ax.scatter(k[~ok], scaled[~ok, idx], s=8, color="tab:red", marker="x")
        if best is not None:
            ax.axhline(space.to_unit(best.params)[idx], color="k", ls="--", lw=0.9)
        dom = space.domains[names[idx]]
        scale = ", log scale" if dom.log else ""
        unit = (units or {}).get(names[idx], "")
        unit = f" {unit}" if unit and unit != "1" else ""
        ax.set_title(f"{names[idx]}\n{dom.low:.3g} to {dom.high:.3g}{unit}{scale}", fontsize=7)
        ax.set_ylim(-0.05, 1.05)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("trial")
    for ax in axes[:, 0]:
        ax.set_ylabel("in domain (0-1)", fontsize=7)
    fig.legend(
        handles=[
            Line2D([], [], ls="none", marker="o", ms=3, color="tab:blue", label="feasible trial"),
            Line2D([], [], ls="none", marker="x", color="tab:red", label="failed trial"),
            Line2D([], [], ls="--", color="k", lw=0.9, label="best trial"),
        ],
        loc="outside lower center",
        ncol=3,
        fontsize=8,
    )
    if title:
        fig.suptitle(title, fontsize=10)
    return _save(fig, path)


def plot_best_execution(trace: ExecutionResult, path: str | Path, title: str = "") -> Path:
    """One execution over time: wrench on the tool (N), TCP position relative to its start
    (mm), orientation (tilt from vertical and yaw, rad); node changes dotted."""
    log = trace.log
    fig, (ax0, ax1, ax2) = plt.subplots(
        3, 1, sharex=True, figsize=(7.0, 7.0), constrained_layout=True
    )
    for i, lab in enumerate(("F_x", "F_y", "F_z")):
        ax0.plot(log.t, log.wrench[:, i], lw=1.0, label=lab)
    ax0.plot(log.t, np.linalg.norm(log.wrench[:, :3], axis=1), color="k", lw=0.8, label="|F|")
    ax0.set_ylabel("force on tool (N)")
    rel = (log.pos - log.pos[0]) * 1e3
    for i, lab in enumerate(("x", "y", "z")):
        ax1.plot(log.t, rel[:, i], lw=1.0, label=lab)
    ax1.set_ylabel("TCP from start (mm)")
    axis_z = wxyz_to_rotation(log.quat).apply([0.0, 0.0, 1.0])[:, 2]
    tilt = np.arccos(np.clip(np.abs(axis_z), 0.0, 1.0))  # tool z vs +-z
    yaw = rz_from_quat(log.quat)
    ax2.plot(log.t, tilt, lw=1.0, label="tilt")
    ax2.plot(log.t, np.unwrap(yaw), lw=1.0, label="yaw")
    ax2.set_ylabel("orientation (rad)")
    ax2.set_xlabel("time since skill start (s)")
    for ax in (ax0, ax1, ax2):
        for v in trace.visits:
            ax.axvline(v.t_enter, color="0.5", lw=0.7, ls=":")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    for v in trace.visits:
        ax0.text(
            v.t_enter,
            1.0,
            f" {v.node}",
            transform=ax0.get_xaxis_transform(),
            fontsize=7,
            va="bottom",
            rotation=30,
        )
    outcome = "success" if trace.success else trace.outcome
    ax0.set_title(
        title or f"{trace.skill}: {outcome}, contact at {trace.t_first_contact:.2f} s",
        fontsize=9,
        pad=18,
    )
    return _save(fig, path)
