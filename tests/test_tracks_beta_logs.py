"""The contact prior's beta weights from logs computed once per grid equal the direct formula (issue 39)."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.tracks.fit_contact import CONTACT_MIN_SD_STEPS, _beta_logs, _beta_weights


def _direct(grid: np.ndarray, p) -> np.ndarray:
    """_beta_weights as it was: the logs of the cell centres computed at every call."""
    m = 1.0 / (1.0 + np.exp(-p[0]))
    kappa = min(np.exp(p[1]), m * (1 - m) * (grid.size / CONTACT_MIN_SD_STEPS) ** 2)
    x = (np.arange(grid.size) + 0.5) / grid.size
    logw = (m * kappa - 1) * np.log(x) + ((1 - m) * kappa - 1) * np.log1p(-x)
    w = np.exp(logw - logw.max())
    return w / w.sum()


@pytest.mark.parametrize("n", [7, 40, 121])
@pytest.mark.parametrize("p", [(0.0, np.log(2.0)), (1.3, 0.2), (-2.0, 4.0), (0.4, 9.0)])
def test_beta_weights_equal_the_direct_formula_bit_for_bit(n, p):
    grid = np.linspace(0.3e-3, 1.5e-3, n)
    w = _beta_weights(grid, np.array(p))
    assert w.shape == (n,) and w.sum() == pytest.approx(1.0, rel=1e-12)
    assert np.array_equal(w, _direct(grid, p))


def test_beta_logs_are_shared_and_read_only():
    a, b = _beta_logs(40)
    assert _beta_logs(40)[0] is a
    with pytest.raises(ValueError):
        a[0] = 0.0
    assert np.all(a < 0) and np.all(b < 0)
