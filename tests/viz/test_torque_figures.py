"""The FR3's joint torque figure draws each execution against the limits."""

import numpy as np
import pytest

from teachfit.viz.torque_figures import plot_joint_torques


def test_joint_torque_figure_is_written(tmp_path):
    t = np.linspace(0.0, 1.0, 101)
    tau = np.column_stack([np.sin(t * k) * lim for k, lim in enumerate([80] * 4 + [10] * 3)])
    path = plot_joint_torques([(t, tau), (t, -tau)], tmp_path / "torques.png")
    assert path.is_file() and path.stat().st_size > 10_000
    assert not list(tmp_path.glob(".*tmp*"))  # written atomically
    with pytest.raises(ValueError, match="no joint torques"):
        plot_joint_torques([], tmp_path / "none.png")
