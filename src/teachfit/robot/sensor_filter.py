"""The wrench sensors' digital low-pass: a second-order Butterworth run at the physics rate.

Real wrench sensing filters on the device at kHz rates before anyone logs at 100 Hz. ATI's Net
F/T (Ehlers et al.'s wrist sensor) samples its gauges at 7 kHz and applies a user-selected low-pass
(Net F/T manual, 9620-05-NET FT, "Low-pass filter": cutoffs 838, 326, 152, 73, 35, 18 or
8 Hz, or none); Franka's ``O_F_ext_hat_K`` / ``tau_ext_hat_filtered`` is likewise a filtered
estimate (cutoff not documented). A 100 Hz log of a first-order 80 Hz filter point-samples
everything up to 500 Hz: the floating tool's 200-500 Hz contact micro-impacts folded into the
0-50 Hz band and read as white noise (std 1.6 N, lag-1 autocorrelation 0). A second-order
Butterworth falls off 40 dB/decade: at 35 Hz the same impacts leave 0.06 N at 100 Hz, at
18 Hz (the default here) 0.02 N, so the decimation to the log rate no longer aliases the kHz
content. 18 Hz keeps the slow press (0-2 Hz) untouched and delays a force step by about
12 ms, about what a 10 ms averaging window (the other way to decimate) would.

The coefficients come from :func:`scipy.signal.butter` (bilinear transform). The floating
tool filters each ``step(n)``'s block of gauge samples with ``scipy.signal.lfilter``
(:class:`LowPass2`); the FR3's compiled tick runs the same recurrence per sample in numba
(:mod:`teachfit.robot.fr3.kernel`), where no library call can enter.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

#: the Net F/T's selectable low-pass cutoffs (Hz); 18 Hz is the default used here
ATI_NETFT_CUTOFFS = (838.0, 326.0, 152.0, 73.0, 35.0, 18.0, 8.0)


def butterworth2(cutoff: float, dt: float) -> np.ndarray:
    """``[b0, b1, b2, a1, a2]`` of a second-order Butterworth low-pass of ``cutoff`` Hz at a
    sample period ``dt`` s (``a0 = 1``). ``cutoff`` must lie below the Nyquist rate."""
    fs = 1.0 / dt
    if not 0.0 < cutoff < 0.5 * fs:
        raise ValueError(f"filter cutoff {cutoff:g} Hz must be within (0, {0.5 * fs:g}) Hz")
    b, a = signal.butter(2, cutoff, fs=fs)
    return np.array([b[0], b[1], b[2], a[1], a[2]], dtype=float)


class LowPass2:
    """A second-order Butterworth low-pass over a vector signal, filtered a block at a time.

    :meth:`filter` takes the samples of one block (``(k, size)``, one row a tick), carries
    the filter's state from block to block (``scipy.signal.lfilter`` with ``zi``) and leaves
    the last filtered sample in ``out`` (read it, do not replace it): the same result as a
    per-tick recursion, at one call per block. :meth:`reset` starts the filter at rest at a
    value (its steady state there, so no transient follows).
    """

    def __init__(self, size: int, cutoff: float, dt: float) -> None:
        self.coef = butterworth2(cutoff, dt)
        self._b = self.coef[:3].copy()
        self._a = np.array([1.0, self.coef[3], self.coef[4]])
        self._zi_unit = signal.lfilter_zi(self._b, self._a)[:, None]  # (2, 1)
        self.zi = np.zeros((2, size))
        self.out = np.zeros(size)

    def reset(self, x: np.ndarray) -> None:
        """The filter at rest at ``x`` (its output and states as after a long constant input)."""
        self.out[:] = x
        self.zi[:] = self._zi_unit * np.asarray(x, dtype=float)

    def filter(self, block: np.ndarray) -> np.ndarray:
        """The filtered samples of ``block`` (k, size); ``out`` becomes the last of them."""
        y, self.zi = signal.lfilter(self._b, self._a, block, axis=0, zi=self.zi)
        self.out[:] = y[-1]
        return y
