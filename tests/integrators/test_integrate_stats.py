"""The statistics of ``sim_core.integrate.driver.integrate``: the minimum step is the dynamics', not
the length of the last step that the solver cuts to land on t_end."""

import numpy as np

from sim_core.integrate.driver import integrate


class Oscillator:
    """y'' = -omega^2 y, omega = 10 rad/s."""

    def rhs(self, t, y):
        return np.array([y[1], -100.0 * y[0]])


def test_min_step_excludes_the_last_step_cut_to_t_end():
    """Steps held at max_step = 1 ms (the oscillator needs ~20 ms for rtol 1e-6, so no step is
    rejected).  Run to t_end = (the time of an accepted step of a longer run) + 1e-9 s: the
    same steps up to there (RK45 is deterministic and the end only cuts the step that would
    pass it), then a final step of ~1e-9 s.  min_step_s is that of the other steps (1e-9 would
    read as a collapse), and the final step is still counted in n_steps."""
    sol = {"rtol": 1e-6, "atol": 1e-9, "n_output": 3, "method": "RK45", "max_step": 1e-3}
    times = []
    integrate(Oscillator(), np.array([1.0, 0.0]), 0.1, sol, lambda t, w: times.append(t))
    steps = np.diff([0.0] + times)
    k = len(times) // 2
    t_end = times[k] + 1e-9
    cut = []
    _, _, st = integrate(Oscillator(), np.array([1.0, 0.0]), t_end, sol,
                         lambda t, w: cut.append(t))
    last = cut[-1] - cut[-2]
    assert st["n_steps"] == k + 2 and last < 1e-8
    assert st["min_step_s"] == min(steps[:k + 1]) > 1e3 * last
