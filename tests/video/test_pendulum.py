"""ballbat.video.pendulum: a filmed pendulum's period, arc and g (synthetic swings of a real, damped pendulum)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ballbat.video.pendulum import arc_radius, fit_swing, pendulum_g

G = 9.81
PX_PER_M = 1800.0  # the bob 0.64 m below the pivot: an arc 1152 px in radius
FPS = 60.0


def _swing(theta0, d=0.64, r=0.016, gamma=0.0, seconds=30.0, sigma_px=0.0, seed=0):
    """Return (t, x, y) of a damped physical pendulum (a sphere r at d) swinging from theta0, filmed in px."""
    k = G * d / (d * d + 0.4 * r * r)  # theta'' = -k sin(theta) - 2 gamma theta'

    def rhs(_, s):
        return [s[1], -k * np.sin(s[0]) - 2 * gamma * s[1]]

    t = np.arange(int(seconds * FPS)) / FPS
    sol = solve_ivp(rhs, (0, t[-1]), [theta0, 0.0], t_eval=t, rtol=1e-11, atol=1e-13, method="DOP853")
    th = sol.y[0]
    rng = np.random.default_rng(seed)
    x = 300.0 + d * PX_PER_M * np.sin(th) + rng.normal(0, sigma_px, t.size)
    y = -900.0 + d * PX_PER_M * np.cos(th) + rng.normal(0, sigma_px, t.size)  # image y down, pivot above
    return t, x, y


def test_small_swing_gives_its_period_and_g():
    t, x, _ = _swing(0.02, sigma_px=0.3)
    fit = fit_swing(t + 5.0, x)  # times not starting at 0
    k = G * 0.64 / (0.64**2 + 0.4 * 0.016**2)
    assert fit.omega == pytest.approx(np.sqrt(k), rel=2e-4)
    assert fit.rms_px == pytest.approx(0.3, rel=0.1)
    assert abs(fit.omega - np.sqrt(k) * (1 - 0.02**2 / 16)) < 3 * fit.se_omega
    assert np.max(np.abs(fit.model(t + 5.0) - x)) < 1.5
    res = pendulum_g(fit, 0.64, bob_radius_m=0.016, theta0_sq=0.02**2)
    assert abs(res.g - G) < 3 * res.se and res.se < 0.005


def test_amplitude_and_bob_corrections_are_the_ones_a_real_pendulum_needs():
    """A 0.25 rad swing runs 0.39 % slow: without the amplitude factor g comes out 0.78 % low, with it within 0.02 %."""
    theta0 = 0.25
    t, x, _ = _swing(theta0)
    fit = fit_swing(t, x)
    bare = pendulum_g(fit, 0.64)  # the bob as a point, the amplitude ignored
    full = pendulum_g(fit, 0.64, bob_radius_m=0.016, theta0_sq=theta0**2)
    assert bare.g / G - 1 == pytest.approx(-(theta0**2) / 8 - 0.4 * 0.016**2 / 0.64**2, abs=3e-4)
    assert full.g == pytest.approx(G, rel=2e-4)
    assert full.amplitude_factor == pytest.approx(1 + theta0**2 / 8)
    assert full.length_eq_m == pytest.approx(0.64 + 0.4 * 0.016**2 / 0.64)


def test_damping_is_fitted_and_the_undamped_frequency_used():
    gamma = 0.02  # the amplitude halves in 35 s
    t, x, _ = _swing(0.05, gamma=gamma, sigma_px=0.2, seed=3)
    fit = fit_swing(t, x)
    assert fit.gamma == pytest.approx(gamma, rel=0.02)
    mean_sq = np.mean((fit.amplitude_at(t) / (0.64 * PX_PER_M)) ** 2)
    res = pendulum_g(fit, 0.64, bob_radius_m=0.016, theta0_sq=mean_sq)
    assert res.g == pytest.approx(G, rel=3e-4)


def test_omega_error_covers_the_truth_as_often_as_it_should():
    """Over 200 noisy small swings, |omega - truth| < se_omega in 68 % (within 4 binomial SE: 0.58-0.78)."""
    k = G * 0.64 / (0.64**2 + 0.4 * 0.016**2)
    truth = np.sqrt(k) * (1 - 0.01**2 / 16)
    t, x0, _ = _swing(0.01, seconds=10.0)
    rng = np.random.default_rng(38)
    hits = 0
    for _ in range(200):
        fit = fit_swing(t, x0 + rng.normal(0, 1.0, t.size))
        hits += abs(fit.omega - truth) < fit.se_omega
    assert 0.58 < hits / 200 < 0.78


def test_arc_radius_is_the_length_in_pixels():
    _, x, y = _swing(0.1, sigma_px=0.3, seed=1)
    radius, se = arc_radius(x, y)
    assert abs(radius - 0.64 * PX_PER_M) < 3 * se
    assert se / radius < 0.02
    with pytest.raises(ValueError, match="no arc bending up"):
        arc_radius(x, -y)  # a pivot below
    with pytest.raises(ValueError, match="at least 4"):
        arc_radius(x[:3], y[:3])


def test_bad_input_is_refused():
    t, x, _ = _swing(0.05, seconds=2.0)  # 1.3 periods
    with pytest.raises(ValueError, match="at least 3 are needed"):
        fit_swing(t, x)
    with pytest.raises(ValueError, match="at least 20"):
        fit_swing(t[:10], x[:10])
    with pytest.raises(ValueError, match="times must increase"):
        fit_swing(t[::-1], x)
    t, x, _ = _swing(0.05, seconds=10.0)
    with pytest.raises(ValueError, match="length must be positive"):
        pendulum_g(fit_swing(t, x), -0.64)
