"""Study coverage (ballbat.studies.coverage): combined intervals, the calibration effect, empty grid points,
study files in SI with tables in the paper's units (issue 22).
"""

from __future__ import annotations

import csv
import io
import itertools
import math

import numpy as np
import pytest
import xarray as xr
from helpers import fake_replicates
from helpers import study_settings as settings
from scipy import stats

from ballbat.studies import batch as study_batch
from ballbat.studies.coverage import COVERAGE_COLUMNS, EmptySweepPoint, combine, coverage, coverage_csv
from ballbat.studies.replicates import STUDY_QUANTITIES
from ballbat.studies.truth import population_truth
from ballbat.units import DEGREE

# ---------------------------------------------------------------------------------------
# studies store SI values with their units; the tables convert for display


def test_study_files_hold_si_and_the_table_prints_paper_units():
    """A slope stored in rad s-1 rad-1 with its unit: coverage.nc keeps SI, coverage.csv prints rpm/deg."""
    from helpers import fake_replicates

    from ballbat.pipeline.ncio import MetadataError, check_metadata
    from ballbat.units import RPM

    rep = fake_replicates(200, se=2.0, spread=2.0, truth=-60.0)
    rep = rep.assign_coords(
        quantity=["spin_theta_slope:baseball:"],
        quantity_name=("quantity", ["spin_theta_slope"]),
        bat=("quantity", [""]),
    )
    rep = rep.assign_coords(units=("quantity", ["rad s-1 rad-1"]))
    cov = coverage(rep)
    assert cov["mean_uncertainty"].values[0, 0] == pytest.approx(2.0)  # SI, as the batches hold it
    assert cov["units"].values[0] == "rad s-1 rad-1" and cov["mean_uncertainty"].attrs["units_from"] == "units"
    assert "units" not in cov["mean_uncertainty"].attrs
    check_metadata(cov, "coverage")  # units_from names a text coordinate along quantity
    row = dict(zip(COVERAGE_COLUMNS, coverage_csv(cov).splitlines()[1].split(","), strict=False))
    assert row["unit"] == "rpm/deg"
    assert float(row["mean_uncertainty"]) == pytest.approx(2.0 / (RPM / DEGREE), rel=1e-5)  # 0.349 rpm/deg
    assert float(row["coverage_95"]) == pytest.approx(float(cov["coverage_95"].values[0, 0]), rel=1e-5)
    with pytest.raises(MetadataError, match="spread: units"):
        check_metadata(cov.drop_vars("units"), "coverage")


# ---------------------------------------------------------------------------------------
# combined intervals


def _with_systematic(n=4000, se=0.01, syst=0.02, seed=0):
    """Replicates of two quantities: one whose estimate is off by a shared calibration error of sd ``syst``
    (reported as its systematic), one without a systematic.
    """
    from helpers import fake_replicates

    rng = np.random.default_rng(seed + 1000)  # not fake_replicates' own stream
    a = fake_replicates(n, se, se, seed=seed)
    a["value"] = a["value"] + syst * rng.standard_normal((n, 1))
    a["systematic"] = (("replicate", "quantity"), np.full((n, 1), syst))
    b = fake_replicates(n, se, se, seed=seed + 1).assign_coords(
        quantity=["e_x_pooled:baseball:"], quantity_name=("quantity", ["e_x_pooled"]), bat=("quantity", [""])
    )
    b["systematic"] = (("replicate", "quantity"), np.full((n, 1), np.nan))
    return xr.concat([a, b], dim="quantity", data_vars="minimal", coords="minimal", compat="override")


def test_the_combined_interval_covers_what_the_statistical_one_misses():
    cov = coverage(_with_systematic()).isel(point=0)
    a, b = cov.isel(quantity=0), cov.isel(quantity=1)
    # statistical only: the interval is sqrt(5) too narrow -> 2 Phi(1.96 / sqrt(5)) - 1 = 62 %
    assert float(a.coverage_95) == pytest.approx(0.62, abs=0.03)
    assert float(a.coverage_95_combined) == pytest.approx(0.95, abs=4 * float(a.coverage_95_combined_err))
    assert float(a.coverage_95_combined) > float(a.coverage_95) + 0.2
    assert float(a.coverage_68_combined) == pytest.approx(0.6827, abs=0.03)
    assert float(a.mean_systematic) == pytest.approx(0.02) and int(a.n_systematic) == 4000
    # no systematic: no combined coverage (not the statistical one again)
    assert np.isnan(float(b.coverage_95_combined)) and int(b.n_systematic) == 0
    assert float(b.coverage_95) == pytest.approx(0.95, abs=0.015)
    text = coverage_csv(coverage(_with_systematic(n=200)))
    rows = list(csv.DictReader(io.StringIO(text.split("# ballbat table:")[0])))
    assert rows[1]["coverage_95_combined"] == "" and rows[0]["coverage_95_combined"] != ""


def test_the_calibration_effect_takes_the_draw_out_of_bias_spread_and_statistical_coverage():
    """Each value is truth + bias + statistical noise + the drawn calibration's shift (4x the SE, as at
    1 px); calibration_effect is minus that shift. Around value + effect the bias is measured to its statistical
    precision (the raw bias is 4x less sharp), the spread is the statistical one and the statistical
    interval covers 95 %; a replicate without an effect (not drawn) leaves the *_calibrated columns NaN.
    """
    from helpers import fake_replicates

    n, se, syst, bias = 4000, 0.01, 0.04, 0.3
    rng = np.random.default_rng(7)
    a = fake_replicates(n, se, se, seed=3)
    shift = syst * rng.standard_normal((n, 1))
    a["value"] = a["value"] + bias * se + shift
    a["systematic"] = (("replicate", "quantity"), np.full((n, 1), syst))
    a["calibration_effect"] = (("replicate", "quantity"), -shift)
    c = coverage(a).isel(point=0, quantity=0)
    assert float(c.bias_over_se_calibrated) == pytest.approx(bias, abs=4 * float(c.bias_over_se_calibrated_err))
    assert float(c.bias_over_se_calibrated_err) == pytest.approx(1 / np.sqrt(n), rel=0.1)
    assert float(c.bias_over_se_err) > 3.5 * float(c.bias_over_se_calibrated_err)  # the draw's spread
    assert float(c.spread_over_se_calibrated) == pytest.approx(1.0, abs=0.04)
    assert float(c.spread_over_se) == pytest.approx(np.hypot(1, 4), rel=0.05)
    # the statistical interval around value + effect, with the bias of 0.3 SE: 2 Phi(1.96 - 0.3) - 1 - ...
    from scipy import stats

    expected = stats.norm.cdf(1.96 - bias) - stats.norm.cdf(-1.96 - bias)
    assert float(c.coverage_95_calibrated) == pytest.approx(expected, abs=4 * float(c.coverage_95_calibrated_err))
    assert float(c.coverage_95) < 0.5  # the raw statistical interval does not cover the draw
    assert int(c.n_calibrated) == n
    plain = coverage(fake_replicates(200, 0.01, 0.01)).isel(point=0, quantity=0)
    assert int(plain.n_calibrated) == 0 and np.isnan(float(plain.bias_over_se_calibrated))
    assert np.isnan(float(plain.coverage_95_calibrated))
    text = coverage_csv(coverage(a))
    header = text.splitlines()[0].split(",")
    assert {"bias_over_se_calibrated", "coverage_95_calibrated", "spread_over_se_calibrated"} <= set(header)


def test_batches_without_a_systematic_still_aggregate():
    from helpers import fake_replicates

    cov = coverage(fake_replicates(200, 0.01, 0.01)).isel(point=0, quantity=0)
    assert np.isnan(float(cov.coverage_95_combined)) and int(cov.n_systematic) == 0


def _grid_replicates(n=150):
    """Fake replicates of one quantity at the 8 corners of a 2 x 2 x 2 grid (coverage ~95 % everywhere)."""
    from helpers import fake_replicates

    table = np.array(list(itertools.product([1.0, 5.0], [12.0, 60.0], [0.5, 1.0])))
    rep = fake_replicates(n * len(table), 0.01, 0.01)
    rep["point"] = ("replicate", np.repeat(np.arange(len(table)), n))
    rep["systematic"] = (("replicate", "quantity"), np.full((n * len(table), 1), 0.001))
    rep.attrs.update(sweep_parameter="pixel_noise_px,impacts_per_bat,contact_ms", sweep_values=table.ravel())
    return rep, table


def test_grid_coverage_table_and_figure(tmp_path):
    from ballbat.plotting import grid_coverage_figure, save_figure
    from workflow_helpers import assert_not_blank

    rep, table = _grid_replicates()
    cov = coverage(rep)
    assert cov.sizes["point"] == 8
    np.testing.assert_array_equal(cov.grid_setting.values, table)
    assert list(cov.parameter.values) == ["pixel_noise_px", "impacts_per_bat", "contact_ms"]
    assert np.all(np.isnan(cov.setting.values))
    text = coverage_csv(cov)
    header = text.splitlines()[0].split(",")
    assert header[:4] == ["setting", "quantity", "ball", "bat"]  # the header the damaged-product guards know
    assert header[-3:] == ["pixel_noise_px", "impacts_per_bat", "contact_ms"]
    assert "coverage_95_combined" in header
    last = text.splitlines()[8].split(",")
    assert last[:2] == ["pixel_noise_px=5 impacts_per_bat=60 contact_ms=1", "e_x"] and last[-3:] == ["5", "60", "1"]
    save_figure(grid_coverage_figure(cov), tmp_path / "grid.png")
    assert_not_blank(tmp_path / "grid.png")


def test_an_empty_grid_point_is_named():
    rep, _ = _grid_replicates(120)
    rep["value"][rep.point.values == 5] = np.nan
    with pytest.raises(EmptySweepPoint, match="pixel_noise_px = 5, impacts_per_bat = 12, contact_ms = 1"):
        coverage(rep)


def test_coverage_arithmetic():
    """Honest errors cover 68 % / 95 %; errors half the truth's spread cover far less, as the normal law says."""
    good = coverage(fake_replicates(20000, 0.01, 0.01)).isel(point=0, quantity=0)
    assert good.coverage_95 == pytest.approx(0.95, abs=4 * float(good.coverage_95_err))
    assert good.coverage_68 == pytest.approx(0.6827, abs=4 * float(good.coverage_68_err))
    assert good.spread_over_se == pytest.approx(1.0, abs=0.03)
    assert abs(float(good.bias_over_se)) < 4 * float(good.bias_over_se_err)
    bad = coverage(fake_replicates(20000, 0.005, 0.01)).isel(point=0, quantity=0)
    assert bad.coverage_95 == pytest.approx(2 * stats.norm.cdf(0.98) - 1, abs=0.01)
    assert bad.spread_over_se == pytest.approx(2.0, abs=0.05)
    # Student's t: with 5 degrees of freedom the 95 % interval is 2.571 SE wide on each side
    t = fake_replicates(20000, 0.01, 0.01 * math.sqrt(5 / 3), dof=5, seed=1)
    t["value"][:] = 1.0 + 0.01 * np.random.default_rng(2).standard_t(5, (20000, 1))
    cov_t = coverage(t).isel(point=0, quantity=0)
    assert cov_t.coverage_95 == pytest.approx(0.95, abs=0.01)


def test_the_truths_own_sampling_error_goes_into_the_bias_error():
    """A design's truth comes from a finite experiment: its scatter, the replicates' own truths' over sqrt(scale).

    Own noise-free estimates scatter by 0.01 about the population value; the truth's experiment
    repeats the design 100 times, so the truth is known to 0.001, a tenth of the reported 0.01.
    The bias's error is the replicates' 0.01 / sqrt(400) = 0.05 SE and that 0.1 in quadrature.
    A conditional truth (each replicate's own) has none.
    """
    n = 400
    a = fake_replicates(n, 0.01, 0.01, seed=3)
    b = fake_replicates(n, 0.01, 0.01, seed=4)
    b = b.assign_coords(quantity=["mu_k_lower_bound:baseball:"], quantity_name=("quantity", ["mu_k_lower_bound"]))
    rep = xr.concat([a, b], dim="quantity", data_vars="minimal", coords="minimal", compat="override")
    rng = np.random.default_rng(5)
    own = 1.0 + 0.01 * rng.standard_normal((n, 2))
    rep["truth"][:] = own
    rep["value"][:] = own + 0.01 * rng.standard_normal((n, 2))
    truths = [{"e_x:baseball:wood": 1.0, "mu_k_lower_bound:baseball:": 1.0}]
    cov = coverage(rep, truths, [100.0]).isel(point=0)
    plain = coverage(rep, truths).isel(point=0)
    te = cov.truth_error_over_se.values
    assert te[0] == pytest.approx(0.1, rel=0.1)
    assert np.isnan(te[1]) and np.isnan(plain.truth_error_over_se.values).all()
    stat = plain.bias_over_se_err.values
    assert cov.bias_over_se_err.values[0] == pytest.approx(math.hypot(stat[0], te[0]), rel=1e-12)
    assert cov.bias_over_se_err.values[1] == stat[1]
    assert cov.bias_over_se.values == pytest.approx(plain.bias_over_se.values)
    text = coverage_csv(coverage(rep, truths, [100.0]))
    assert "truth_error_over_se" in text.splitlines()[0].split(",")


@pytest.mark.slow  # seconds (quiet machine): more than a unit test may take
def test_replicates_cover_the_truth(config, balls, bats):
    """A fast coverage check of the whole chain: 40 replicates of the default experiment (raw tracks).

    e_x of every bat and ball: 280 intervals cover their truth about 95 % of the time and the
    estimates scatter as their standard errors say. (The 1000-replicate calibration study,
    `make study`, is the full check; its figures are in docs/studies.md and the issue notes.)
    """
    s = settings(config, replicates=40, batch_size=40, truth_impacts=400)
    batch = study_batch.run(s, 0, balls, bats)
    assert batch.sizes == {"replicate": 40, "quantity": 21}
    truths = [population_truth(s, 0, balls, bats)]
    cov = coverage(combine([batch]), truths).isel(point=0)
    ex = cov.where(cov.quantity_name == "e_x", drop=True)
    n = int(ex.n_replicates.sum())
    assert n == 280
    c95 = float((ex.coverage_95 * ex.n_replicates).sum()) / n
    assert 0.90 <= c95 <= 0.99, c95
    ratio = float(ex.spread_over_se.mean())
    assert 0.85 <= ratio <= 1.15, ratio
    # every recorded quantity has its truth and an honest label of its uncertainty
    assert set(cov.quantity_name.values) == set(STUDY_QUANTITIES)
    assert np.all(cov.n_replicates.values == 40)
    assert all(cov.error_kind.values)
    # eta^2's interval uses the Bell-McCaffrey degrees of freedom of its bat-stratified sandwich
    eta = batch.dof.isel(quantity=np.flatnonzero(batch.quantity_name.values == "eta2")).values
    assert eta.size == 80 and np.all((eta > 5) & (eta < 60)) and not np.all(eta == np.round(eta))
    assert "centred within bats" in str(cov.error_kind.values[list(cov.quantity_name.values).index("eta2")])
    # implied e_y's interval has n - k degrees of freedom, k = the ball's bats + 1 (its variance's n / (n - k)):
    # the Eq. ratio slope's n - 1 less the ball's bats (3 baseball, 4 softball)
    for ball, n_bats in (("baseball", 3), ("softball", 4)):
        dof_ey = batch.dof.sel(quantity=f"e_y_implied:{ball}:").values
        dof_ratio = batch.dof.sel(quantity=f"tan_ratio_slope:{ball}:").values
        np.testing.assert_array_equal(dof_ratio - dof_ey, n_bats)


def test_combined_interval_takes_welch_satterthwaite_degrees_of_freedom():
    """A combined interval t x sqrt(u^2 + s^2) with a stated (exact) systematic s needs nu_eff, not u's nu.

    With the statistical t quantile of 10 degrees of freedom and a systematic 3x the statistical
    error, the interval is 13 % too wide and covers about 97.5 %; the robustness grid showed it as
    99-100 % at 12-30 impacts per bat (docs/studies.md). With nu_eff = nu (u^2 + s^2)^2 / u^4
    (GUM G.4) it covers 95 %.
    """
    from ballbat.studies.coverage import _t
    from ballbat.studies.records import combined_dof

    assert combined_dof(1.0, 0.0, 10.0) == 10.0
    assert combined_dof(1.0, 1.0, 10.0) == 40.0
    assert combined_dof(0.0, 1.0, 10.0) == np.inf
    rng = np.random.default_rng(2)
    n, nu, s = 40000, 10.0, 3.0
    u = np.sqrt(rng.chisquare(nu, n) / nu)  # the stated statistical error, true value 1
    d = rng.standard_normal(n) + s * rng.standard_normal(n)
    total = np.hypot(u, s)
    ws = np.mean(np.abs(d) <= _t(0.95, combined_dof(u, s, nu)) * total)
    held = np.mean(np.abs(d) <= _t(0.95, np.full(n, nu)) * total)
    assert abs(ws - 0.95) < 0.005, ws
    assert held > 0.97, held


def test_the_interval_quantiles_are_scipy_stats_own_to_the_bit():
    """coverage._t (scipy.special's ndtri and stdtrit) gives scipy.stats.norm.ppf's and t.ppf's numbers."""
    from ballbat.studies.coverage import _t

    dof = np.array([np.inf, np.nan, 0.0, -1.0, 1.0, 2.0, 2.5, 11.6, 17.457, 55.398, 1e4, 1e7])
    for q in (0.6826894921370859, 0.95):
        got = _t(q, dof)
        safe = np.where(np.isfinite(dof) & (dof > 0), dof, 1.0)
        want = np.where(
            np.isfinite(dof), np.where(dof > 0, stats.t.ppf(0.5 + q / 2, safe), np.nan), stats.norm.ppf(0.5 + q / 2)
        )
        np.testing.assert_array_equal(got, want)
    assert _t(0.95, np.array([np.inf]))[0] == pytest.approx(1.959964, abs=1e-6)
