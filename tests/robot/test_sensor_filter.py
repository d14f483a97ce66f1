"""The wrench sensors' second-order Butterworth: scipy's filter, block by block or per tick
(the FR3's compiled recursion), alias-safe."""

import numpy as np
import pytest
from scipy import signal

from teachfit.robot.fr3.kernel import _biquad
from teachfit.robot.sensor_filter import LowPass2, butterworth2


def test_blocks_and_the_compiled_per_tick_recursion_match_one_scipy_pass_from_rest():
    rng = np.random.default_rng(0)
    x = 2.0 + rng.normal(0.0, 1.0, (500, 3))
    lp = LowPass2(3, 18.0, 0.001)
    lp.reset(np.full(3, 2.0))
    blocks = np.concatenate([lp.filter(x[i : i + 10]) for i in range(0, 500, 10)])
    b, a = signal.butter(2, 18.0, fs=1000.0)
    ref = signal.lfilter(b, a, x, axis=0, zi=signal.lfilter_zi(b, a)[:, None] * 2.0)[0]
    np.testing.assert_allclose(blocks, ref, atol=1e-12)
    assert np.array_equal(lp.out, blocks[-1])
    coef, y, z = butterworth2(18.0, 0.001), np.zeros(3), np.zeros((2, 3))
    b0, b1, b2, a1, a2 = coef
    z[1] = (b2 - a2) * 2.0
    z[0] = (b1 - a1) * 2.0 + z[1]  # at rest at 2, as LowPass2.reset
    ticks = []
    for row in x:
        _biquad(coef, row, y, z)
        ticks.append(y.copy())
    np.testing.assert_allclose(np.array(ticks), ref, atol=1e-10)


def test_it_passes_slow_force_and_stops_what_100_hz_sampling_would_alias():
    dt = 0.001
    t = np.arange(4000) * dt
    gains = {}
    for f in (1.0, 300.0):
        lp = LowPass2(1, 18.0, dt)
        y = lp.filter(np.sin(2 * np.pi * f * t)[:, None])[2000:, 0]
        gains[f] = np.ptp(y) / 2
    assert gains[1.0] == pytest.approx(1.0, abs=0.01)
    assert gains[300.0] < 0.005  # 40 dB/decade: a first-order 80 Hz filter passes 0.26


def test_cutoff_above_nyquist_is_refused():
    with pytest.raises(ValueError, match="within"):
        butterworth2(600.0, 0.001)
