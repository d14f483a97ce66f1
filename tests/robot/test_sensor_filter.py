"""The wrench sensors' second-order Butterworth: scipy's filter, per sample, alias-safe."""

import numpy as np
import pytest
from scipy import signal

from teachfit.robot.sensor_filter import LowPass2, butterworth2


def test_per_sample_filter_matches_scipy_and_starts_at_rest():
    rng = np.random.default_rng(0)
    x = 2.0 + rng.normal(0.0, 1.0, (500, 3))
    lp = LowPass2(3, 35.0, 0.001)
    lp.reset(np.full(3, 2.0))
    out = []
    for row in x:
        lp.update(row)
        out.append(lp.out.copy())
    b, a = signal.butter(2, 35.0, fs=1000.0)
    ref = signal.lfilter(b, a, x, axis=0, zi=signal.lfilter_zi(b, a)[:, None] * 2.0)[0]
    np.testing.assert_allclose(np.array(out), ref, atol=1e-12)


def test_it_passes_slow_force_and_stops_what_100_hz_sampling_would_alias():
    dt = 0.001
    t = np.arange(4000) * dt
    gains = {}
    for f in (1.0, 300.0):
        lp = LowPass2(1, 35.0, dt)
        ys = []
        for v in np.sin(2 * np.pi * f * t):
            lp.update(np.array([v]))
            ys.append(lp.out[0])
        gains[f] = np.ptp(ys[2000:]) / 2
    assert gains[1.0] == pytest.approx(1.0, abs=0.01)
    assert gains[300.0] < 0.02  # 40 dB/decade: a first-order 80 Hz filter passes 0.26


def test_cutoff_above_nyquist_is_refused():
    with pytest.raises(ValueError, match="Nyquist|within"):
        butterworth2(600.0, 0.001)
