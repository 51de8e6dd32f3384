"""ballbat.video.fall: a filmed free flight's acceleration, its value and its errors' coverage (synthetic parabolas)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from ballbat.video.fall import fit_fall, mark_agreement

G = 9.81
M_PER_PX = 1 / 400.0  # a metre stick 400 px long


def _parabola(rng, n, fps, sigma_px, a=G, m_per_px=M_PER_PX):
    t = np.arange(n) / fps
    y = 200.0 - 150.0 * t + 0.5 * (a / m_per_px) * t**2  # tossed up (image y down), then falling
    return t, y + rng.normal(0.0, sigma_px, n)


def test_noise_free_parabola_gives_its_acceleration_and_start():
    t, y = _parabola(np.random.default_rng(0), 11, 15.0, 0.0)
    fit = fit_fall(t + 2.0, y, M_PER_PX)  # times not starting at 0: y0, v0 are at t = 0
    assert fit.a == pytest.approx(G, rel=1e-10)
    assert fit.a_px_s2 == pytest.approx(G / M_PER_PX, rel=1e-10)
    assert fit.se_stat < 1e-9 and fit.rms_px < 1e-9
    assert np.max(np.abs(fit.residuals_px(t + 2.0, y))) < 1e-8
    # the parabola's value at t = 0 and slope there, from y(t') with t' = t - 2
    a_px = G / M_PER_PX
    assert fit.v0_px_s == pytest.approx(-150.0 - a_px * 2.0, rel=1e-9)
    assert fit.y0_px == pytest.approx(200.0 + 150.0 * 2.0 + 0.5 * a_px * 4.0, rel=1e-9)


def test_statistical_error_covers_as_students_t():
    """Over 2000 noisy parabolas (11 points, 8 degrees of freedom), |a - truth| < k se_stat as often as t_8 says.

    The expected fractions are Student's t with n - 3 degrees of freedom (the scatter is estimated);
    the tolerance is 4 binomial standard errors of 2000 draws.
    """
    rng = np.random.default_rng(38)
    pulls = []
    for _ in range(2000):
        t, y = _parabola(rng, 11, 15.0, 0.8)
        fit = fit_fall(t, y, M_PER_PX)
        pulls.append((fit.a - G) / fit.se_stat)
    pulls = np.abs(pulls)
    for k in (1.0, 2.0):
        p = 2 * stats.t.cdf(k, 8) - 1
        tol = 4 * np.sqrt(p * (1 - p) / 2000)
        assert abs(np.mean(pulls < k) - p) < tol, (k, np.mean(pulls < k), p)


def test_weights_and_scale_and_time_systematics_cover_together():
    """Points of unequal scatter weighted by it, a scale drawn off by its error and a frame interval by its own.

    With 60 points the scatter is well known, so the combined error's pulls are close to normal:
    68.3 % within 1, 95.4 % within 2 (4 binomial standard errors of 2000 draws).
    """
    rng = np.random.default_rng(7)
    pulls = []
    for _ in range(2000):
        scale = M_PER_PX * (1 + rng.normal(0, 0.02))  # the true scale; the fit is given M_PER_PX +- 2 %
        dt = (1 + rng.normal(0, 0.005)) / 120.0  # the true frame interval; the fit is given 1 / 120 s +- 0.5 %
        sig = np.where(np.arange(60) % 2, 0.3, 1.2)
        t = np.arange(60) * dt
        y = 50.0 - 300.0 * t + 0.5 * (G / scale) * t**2 + rng.normal(0, sig)
        fit = fit_fall(np.arange(60) / 120.0, y, M_PER_PX, m_per_px_err=0.02 * M_PER_PX, dt_rel_err=0.005, sigma_px=sig)
        pulls.append((fit.a - G) / fit.se)
    pulls = np.abs(pulls)
    assert fit.se_scale == pytest.approx(0.02 * abs(fit.a))
    assert fit.se_time == pytest.approx(0.01 * abs(fit.a))
    for k, p in ((1.0, 0.6827), (2.0, 0.9545)):
        assert abs(np.mean(pulls < k) - p) < 4 * np.sqrt(p * (1 - p) / 2000), (k, np.mean(pulls < k))


def test_z_against_a_reference():
    t, y = _parabola(np.random.default_rng(1), 11, 15.0, 0.5, a=10.0)
    fit = fit_fall(t, y, M_PER_PX, m_per_px_err=0.01 * M_PER_PX)
    assert fit.z(G, 0.01) == pytest.approx((fit.a - G) / np.sqrt(fit.se**2 + 0.01**2))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"t_s": [0, 1, 2], "y_px": [0, 1, 4]}, "3 points; at least 4"),
        ({"t_s": [0, 1, 2, 3], "y_px": [0, 1, 4]}, "4 times but 3 positions"),
        ({"t_s": [0, 1, 2, 3], "y_px": [0, 1, np.nan, 9]}, "y_px has a non-finite value at index 2"),
        ({"t_s": [0, 0, 1, 1], "y_px": [0, 1, 4, 9]}, "fewer than 3 distinct times"),
        ({"t_s": [0, 1, 2, 3], "y_px": [0, 1, 4, 9], "sigma_px": [1, 0, 1, 1]}, "sigma_px must be positive (index 1)"),
        ({"t_s": [0, 1, 2, 3], "y_px": [0, 1, 4, 9], "m_per_px": 0.0}, "m_per_px must be positive"),
    ],
)
def test_bad_input_is_named(kwargs, message):
    kwargs = {"m_per_px": 0.001, **kwargs}
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        fit_fall(**kwargs)


def test_mark_agreement_matches_frames_and_splits_offset_from_scatter():
    tracked = (np.array([3, 4, 5, 6, 9]), np.array([10.0, 20, 30, 40, 90]), np.array([5.0, 6, 7, 8, 11]))
    marks = (np.array([2, 4, 5, 6, 9]), np.array([0.0, 20.5, 30.5, 40.5, 91.5]), np.array([0.0, 7.0, 8.0, 9.0, 12.0]))
    ag = mark_agreement(tracked, marks, pixel_shift=0.5)
    assert ag.frames.tolist() == [4, 5, 6, 9]
    assert ag.dx.tolist() == [0.0, 0.0, 0.0, -1.0]
    assert ag.offset == pytest.approx((-0.25, -0.5))
    assert ag.rms == pytest.approx((np.std([0, 0, 0, -1.0]), 0.0))
    with pytest.raises(ValueError, match="1 frames in common"):
        mark_agreement((np.array([1, 2]), np.zeros(2), np.zeros(2)), (np.array([2, 3]), np.zeros(2), np.zeros(2)))
