"""Joint torques of the FR3 over time, against the arm's torque limits.

One column per execution: joints 1-4 (limit 87 N·m) on top, joints 5-7 (12 N·m) below, the
limits dashed. The torques are those the torque law commanded (gravity compensation included),
sampled at the end of each command period (``FR3Robot.torque_traces``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from teachfit.robot.fr3.params import TAU_MAX  # noqa: E402

_GROUPS = ((0, 4), (4, 7))  # joints sharing a limit


def plot_joint_torques(
    traces: Sequence[tuple[np.ndarray, np.ndarray]],
    path: str | Path,
    titles: Sequence[str] | None = None,
    tau_max: Sequence[float] = TAU_MAX,
) -> Path:
    """Draw each ``(t (T,) s, tau (T, 7) N·m)`` in ``traces`` to the image ``path``."""
    if not traces:
        raise ValueError("no joint torques to plot")
    path = Path(path)
    k = len(traces)
    fig, axes = plt.subplots(
        2, k, figsize=(4.6 * k, 5.5), squeeze=False, sharex="col", constrained_layout=True
    )
    limit = np.asarray(tau_max, dtype=float)
    for j, (t, tau) in enumerate(traces):
        tau = np.asarray(tau).reshape(len(t), -1)
        for row, (lo, hi) in enumerate(_GROUPS):
            ax = axes[row, j]
            for i in range(lo, hi):
                ax.plot(t, tau[:, i], lw=1.0, label=f"joint {i + 1}")
            cap = float(limit[lo:hi].max())
            for sign in (1, -1):
                ax.axhline(sign * cap, color="k", ls="--", lw=0.8)
            ax.set_ylim(-1.1 * cap, 1.1 * cap)
            ax.set_ylabel("joint torque (N·m)")
            ax.grid(alpha=0.3)
            if j == 0:
                ax.legend(fontsize=7, ncol=2, loc="lower right")
        axes[0, j].set_title(titles[j] if titles else f"execution {j}", fontsize=9)
        axes[1, j].set_xlabel("time (s)")
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    tmp.replace(path)
    return path
