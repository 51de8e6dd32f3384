"""Fit helpers (ballbat.fitting): e_y's variance, the bias of picking the largest value."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat import fitting


@pytest.mark.slow  # more than 2 s
def test_largest_value_removes_most_of_the_bias_of_picking_the_largest():
    """Eq. muk's bound is the largest true tan(psi - theta); the largest *measured* value is biased high.

    48 values crowded near their top, each measured to 0.005-0.015 (harder than the studies'
    data, where the correction leaves |bias| <= 0.05 SE): the largest measurement overshoots
    the largest true value by about 1.0 of its uncertainty; the bootstrap correction
    (:func:`ballbat.fitting.largest_value`) takes off more than half of it (0.4 is left).
    With one value far above the others there is nothing to correct.
    """
    from ballbat.fitting import largest_value

    rng = np.random.default_rng(1)
    raw, corrected = [], []
    for _ in range(300):
        t = 0.4 * np.sqrt(rng.uniform(0, 0.2, 48))
        sig = 0.01 * rng.uniform(0.5, 1.5, 48)
        y = t + sig * rng.standard_normal(48)
        k = np.argmax(y)
        raw.append((y[k] - t.max()) / sig[k])
        corrected.append((largest_value(y, sig) - t.max()) / sig[k])
    raw, corrected = np.mean(raw), np.mean(corrected)
    assert raw > 0.7, raw
    assert abs(corrected) < raw / 2, (raw, corrected)
    y = np.array([0.1, 0.12, 0.11, 0.5])
    assert largest_value(y, np.full(4, 0.01)) == pytest.approx(0.5, abs=1e-6)
    assert largest_value(np.array([0.2, np.nan]), np.array([0.01, 0.01])) == pytest.approx(0.2, abs=1e-6)


@pytest.mark.parametrize("by_impact", [True, False])
def test_largest_value_is_the_full_grid_number_to_the_bit(monkeypatch, by_impact):
    """The grid points where log Phi is -0.0 are left out of the evaluation, not out of the sum: same bits.

    The full (grid x impacts) evaluation, as :func:`ballbat.fitting.largest_value` made it
    before it skipped them, on values whose spreads differ by 10x, by each value's run of grid
    points and by blocks of grid points (:data:`ballbat.fitting.LARGEST_BY_IMPACT`), and
    log Phi(z) is -0.0 everywhere past :data:`ballbat.fitting.LOG_NDTR_ZERO` (the skipped points).
    """
    if not by_impact:
        monkeypatch.setattr(fitting, "LARGEST_BY_IMPACT", 0)
    from scipy.special import log_ndtr

    def full_grid(y, sigma):
        top = float(np.max(y))
        m = np.linspace(top - 10 * sigma.max(), float(np.max(y + 10 * sigma)), fitting.LARGEST_GRID)
        cdf = np.exp(np.sum(log_ndtr((m[:, None] - y[None, :]) / sigma[None, :]), axis=1))
        return 2 * top - float(m[0] + np.trapezoid(1.0 - cdf, m))

    rng = np.random.default_rng(7)
    for n in (1, 5, 48, 130):
        y = rng.normal(0.2, 0.05, n)
        sigma = 0.01 * rng.uniform(0.2, 2.0, n)
        assert fitting.largest_value(y, sigma) == full_grid(y, sigma)
    z = np.concatenate([np.linspace(fitting.LOG_NDTR_ZERO - 2.3, 60.0, 200001), [1e3, 1e300, np.inf]])
    assert np.all(log_ndtr(z) == 0.0)
    assert log_ndtr(37.0) < 0.0  # the threshold is not far beyond where it has to be


def test_e_y_variance_forms():
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=20), rng.normal(size=20)
    h1, h2 = rng.uniform(0, 0.3, 20), rng.uniform(0, 0.3, 20)
    plain = fitting.e_y_variance(a, b, np.zeros(20), np.zeros(20), 4, "hc2")
    assert plain == pytest.approx(np.sum((a - b) ** 2))
    assert fitting.e_y_variance(a, b, h1, h2, 4, "hc0k") == pytest.approx(np.sum((a - b) ** 2) * 20 / 16)
    one_part = fitting.e_y_variance(a, 0 * b, h1, h2, 4, "hc3")
    assert one_part == pytest.approx(np.sum((a / (1 - h1)) ** 2))
    with pytest.raises(ValueError, match="hc3"):
        fitting.e_y_variance(a, b, h1, h2, 4, "hc9")
