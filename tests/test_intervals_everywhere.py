"""Issue 36: e_x's intrinsic-scatter term (Paule-Mandel tau) and implied e_y's leverage-corrected sandwich."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat import fitting, linefit
from ballbat.linefit import eiv_line, paule_mandel, scatter_interval
from ballbat.stages.fit_ex import fit_ex_table


def _scattered_line(rng, n, slope, tau, sx=0.05, sy=0.05):
    """Points whose own slope is ``slope`` +- ``tau``, x and y measured with noise sx, sy."""
    x_true = rng.uniform(0.5, 2.0, n)
    y_true = (slope + tau * rng.standard_normal(n)) * x_true
    x = x_true + sx * rng.standard_normal(n)
    y = y_true + sy * rng.standard_normal(n)
    jx = np.tile([1.0, 0.0], (n, 1))
    jy = np.tile([0.0, 1.0], (n, 1))
    sigma = np.tile([sx, sy], (n, 1))
    return x, y, jx, jy, sigma


def test_paule_mandel_solves_its_equation():
    # v0 = g = 1, every r^2 = 3: n 3 / (1 + tau^2) = n - 1
    n = 10
    tau2 = paule_mandel(np.full(n, np.sqrt(3.0)), np.ones(n), np.ones(n), n - 1)
    assert tau2 == pytest.approx(3.0 * n / (n - 1) - 1.0, rel=1e-8)


def test_paule_mandel_is_zero_when_the_errors_explain_the_scatter():
    assert paule_mandel(np.full(5, 0.5), np.ones(5), np.ones(5), 4) == 0.0


def test_paule_mandel_refuses_no_degrees_of_freedom():
    with pytest.raises(ValueError, match="degree of freedom"):
        paule_mandel(np.ones(1), np.ones(1), np.ones(1), 0)


def test_scatter_interval_brackets_the_estimate():
    rng = np.random.default_rng(1)
    r = rng.normal(0.0, 2.0, 40)
    lo, hi = scatter_interval(r, np.ones(40), np.ones(40), 39)
    tau = np.sqrt(paule_mandel(r, np.ones(40), np.ones(40), 39))
    assert lo < tau < hi


def test_eiv_line_estimates_the_intrinsic_scatter():
    x, y, jx, jy, sigma = _scattered_line(np.random.default_rng(2), 4000, 1.3, 0.05)
    fit = eiv_line(x, y, jx, jy, sigma, scatter=True)
    assert fit.scatter == pytest.approx(0.05, abs=0.005)
    assert fit.scatter_ci_low < 0.05 < fit.scatter_ci_high
    assert fit.slope == pytest.approx(1.3, abs=4 * fit.slope_err)


def test_eiv_line_without_scatter_is_unchanged_where_tau_is_zero():
    x, y, jx, jy, sigma = _scattered_line(np.random.default_rng(3), 30, 1.3, 0.0)
    plain = eiv_line(x, y, jx, jy, sigma)
    with_term = eiv_line(x, y, jx, jy, sigma, scatter=True)
    if with_term.scatter == 0:
        assert with_term.slope == pytest.approx(plain.slope, rel=1e-12)
        assert with_term.slope_err == pytest.approx(plain.slope_err, rel=1e-12)
    assert np.isnan(plain.scatter)


def _coverage(scatter: bool, reps: int = 400) -> float:
    rng = np.random.default_rng(4)
    hits = 0
    for _ in range(reps):
        x, y, jx, jy, sigma = _scattered_line(rng, 15, 1.3, 0.08, sx=0.02, sy=0.02)
        fit = eiv_line(x, y, jx, jy, sigma, scatter=scatter)
        hits += fit.slope_ci_low <= 1.3 <= fit.slope_ci_high
    return hits / reps


def test_scatter_term_gives_intervals_that_cover():
    # weights from the measurement errors alone are wrong when the slope scatters; with tau they are right
    assert 0.92 <= _coverage(True) <= 0.98


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


def test_fit_ex_declares_the_scatter_with_units_and_words():
    table = fit_ex_table(False, 0.5)
    for name in ("e_x_scatter", "e_x_scatter_ci_low", "e_x_scatter_ci_high"):
        assert table[name].units == "1"
        assert table[name].dims == ("ball", "bat")
        assert "e_x_scatter" in table[name].long_name or "tau" in table[name].long_name


def test_the_switch_turns_the_term_off(monkeypatch):
    x, y, jx, jy, sigma = _scattered_line(np.random.default_rng(6), 200, 1.3, 0.1)
    monkeypatch.setattr(linefit, "SCATTER_TERM", False)
    assert np.isnan(eiv_line(x, y, jx, jy, sigma, scatter=True).scatter)


def _dataset():
    from ballbat.config_checks import load_config

    return load_config()["datasets"]["synthetic"]


def test_sweep_sets_scatter_psi_range_and_spin_noise():
    from ballbat.studies.sweeps import point_dataset

    base = _dataset()
    ds = point_dataset(base, ["e_x_scatter", "psi_max_scale", "spin_pixel_noise_px"], [0.02, 0.4, 3.5])
    assert ds["synthetic"]["e_x_scatter"] == 0.02
    for ball, (lo, hi) in base["synthetic"]["psi_deg"].items():
        assert ds["synthetic"]["psi_deg"][ball] == pytest.approx([lo, 0.4 * hi])
    assert ds["render"]["cameras"]["spin"]["pixel_noise_px"] == 3.5
    assert ds["render"]["cameras"]["swing"]["pixel_noise_px"] == base["render"]["cameras"]["swing"]["pixel_noise_px"]


@pytest.mark.parametrize(
    ("parameter", "value", "words"),
    [
        ("e_x_scatter", -0.01, "e_x_scatter must lie"),
        ("psi_max_scale", 0.0, "psi_max_scale must lie"),
        ("spin_pixel_noise_px", 0.0, "must be positive"),
    ],
)
def test_sweep_refuses_bad_values(parameter, value, words):
    from ballbat.studies.sweeps import check_sweep

    problems = check_sweep(_dataset(), parameter, [value], "studies.x")
    assert any(words in p for p in problems)
