"""Stress filter (SIMULTECH 2020 Eq. 53; docs/model.md#input-filter): increasing h removes the
high-frequency content of the boom-2 tip velocity while the low-frequency response changes
little.

Theory (docs/model.md#input-filter): the filter turns a mode omega into
omega/sqrt(1 + h^2 omega^2/6) with damping ratio zeta ~ h omega / 4.  Cutoff f_c = 20 Hz
(omega_c = 126 1/s): above it zeta >= 0.16 for h = 0.005 s but only >= 0.063 for h = 0.002 s;
over the ~0.3 s of free vibration after the drive stops a single mode's energy ratio is
<= exp(-2 (0.16 - 0.063) 126 0.3) ~ 1e-3, so the high-band energy must drop clearly (assert: by
more than 2x; measured 0.112 -> 0.026, ratio 0.24).  Below f_low = 5 Hz, zeta <= 0.04
(h = 0.005) and the frequency shift <= 0.2 %: the low band (dominated by the driven motion) must
agree to 10 % (RMS of the difference / RMS).

Coarse, luffing only, gravity off (the drive excites the booms: Eq. 52 acceleration jumps at
t_b and t_c), 2 sub-elements per boom, compressed profile.  Runtime 4 + 6 min on the shared
machine (2768 and 5840 RHS) -> @slow.
"""

import numpy as np
import pytest

from sim_core.systems.folding.build import FoldingParams, simulate_folding

T_END = 0.6
N_OUT = 601          # 1 kHz sampling (Nyquist 500 Hz)


def _run(h):
    p = FoldingParams(n_nodes=3, gravity=0.0, filter_h=h, t1=0.1, t2=0.1, t3=0.1,
                      stage_starts=(0.0, 10.0, 20.0), cyl1_stroke=0.05, rest_k=0.0)
    return simulate_folding(p, t_end=T_END, n_output=N_OUT, rtol=1e-6, atol=1e-8)


@pytest.fixture(scope="module")
def runs():
    return {h: _run(h) for h in (0.002, 0.005)}


def _bands(res, f_low=5.0, f_c=20.0):
    """Energy above f_c and the band-limited (<= f_low) signal of the tip velocity; a Hann
    window removes the end-discontinuity leakage (without it the leakage of the driven motion,
    ~1e3 (m/s)^2 above 40 Hz, swamps the vibration content of ~1e-4)."""
    v = res["tip_velocity"]
    t = res.t
    dt = t[1] - t[0]
    V = np.fft.rfft((v - v.mean(axis=0)) * np.hanning(len(t))[:, None], axis=0)
    f = np.fft.rfftfreq(len(t), dt)
    high = np.sum(np.abs(V[f > f_c]) ** 2)
    low = np.fft.irfft(np.where((f <= f_low)[:, None], V, 0), n=len(t), axis=0)
    return high, low


@pytest.mark.slow
def test_filter_removes_high_frequencies(runs):
    e_small, low_small = _bands(runs[0.002])
    e_large, low_large = _bands(runs[0.005])
    assert e_small > 0                                        # there is content to remove
    assert e_large < 0.5 * e_small, (e_large, e_small)
    rms = np.sqrt(np.mean(low_small ** 2))
    diff = np.sqrt(np.mean((low_large - low_small) ** 2))
    assert diff < 0.1 * rms, (diff, rms)
