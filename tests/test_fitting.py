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
    """The grid points where log Phi is negligible are left out of the evaluation, not out of the sum: same bits.

    The full (grid x impacts) evaluation, as :func:`ballbat.fitting.largest_value` made it
    before it skipped them, on values whose spreads differ by 10x, by each value's run of grid
    points and by blocks of grid points (:data:`ballbat.fitting.LARGEST_BY_IMPACT`), and
    log Phi(z) is below 7.7e-24 in magnitude everywhere past :data:`ballbat.fitting.LOG_NDTR_NEGLIGIBLE`
    (the skipped points), and exactly -0.0 from 37.7 on.
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
    for n in (1, 5, 48, 130, 400):
        for spread in (0.05, 0.005):  # values spread over many of their errors, and within a few
            y = rng.normal(0.2, spread, n)
            sigma = 0.01 * rng.uniform(0.2, 2.0, n)
            assert fitting.largest_value(y, sigma) == full_grid(y, sigma)
    z = np.concatenate([np.linspace(fitting.LOG_NDTR_NEGLIGIBLE, 60.0, 200001), [1e3, 1e300, np.inf]])
    assert np.all(-7.7e-24 <= log_ndtr(z)) and np.all(log_ndtr(z) <= 0.0)
    assert np.all(log_ndtr(np.linspace(37.7, 60.0, 1001)) == 0.0)
    assert log_ndtr(fitting.LOG_NDTR_NEGLIGIBLE) < 0.0  # the terms left out are not all zero


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


def _with_contact_shift(rec, rel: float, ball: str):
    """``rec`` with contact shifts on the impacts of ``ball`` (0 elsewhere): v_bat by +-``rel`` v_bat, theta by
    +-``rel`` rad (theta moves psi, hence the Eq. ratio slope; v_bat moves e_x).
    """
    on = (rec["ball"].values == ball).astype(float)
    sides = np.array([1.0, -1.0])[:, None]
    return rec.assign(
        contact_shift_v_bat=(("shift", "impact"), sides * rel * on * rec["v_bat"].values, {"units": "m s-1"}),
        contact_shift_theta=(("shift", "impact"), sides * rel * on, {"units": "rad"}),
    )


def test_the_contact_error_is_the_refits_half_difference_in_quadrature(config, balls, bats):
    """A shift common to one ball type's impacts (its contact population at +-1 sigma) is that ball's error alone.

    The other ball's numbers do not move (its shifts are 0); the shifted ball's e_x, pooled e_x,
    Eq. ratio slope and implied e_y get half the change of the same estimators refitted with
    every v_bat of that ball at (1 +- 0.2 %) and theta +- 2 mrad, added in quadrature to their statistical errors
    (the rank-one covariance delta delta' of the shared shift), their intervals widened alike.
    """
    from helpers import NORM, REC

    from ballbat.stages import fit_ex, normalize, reconstruct, simulate
    from ballbat.synthetic import SyntheticSettings

    s = SyntheticSettings(**{**config["datasets"]["synthetic"]["synthetic"], "seed": 5})
    rec = reconstruct.run(REC, normalize.run(NORM, simulate.run(s, balls, bats)), balls, bats)
    rec = rec.drop_vars([k for k in rec.data_vars if k.startswith("truth_")])
    settings = fit_ex.FitExSettings(mu_k_example=0.5, systematic=False, check_physical=True, mu_k_bound=True)
    plain = fit_ex.run(settings, rec)
    got = fit_ex.run(settings, _with_contact_shift(rec, 2e-3, "softball"))
    sides = []
    for sign in (1.0, -1.0):
        moved = _with_contact_shift(rec, 2e-3, "softball")
        moved = fitting.contact_shifted_impacts(moved, 0 if sign > 0 else 1)
        sides.append(fit_ex.results_dataset(fitting.analyze_impacts(moved, 0.5, False, core=True)))
    for q in fitting.CONTACT_QUANTITIES:
        extra = 0.5 * np.abs(sides[0][q] - sides[1][q]).sel(ball="softball")
        assert np.all((extra > 0) | np.isnan(extra))
        np.testing.assert_allclose(got[f"{q}_err_contact"].sel(ball="softball"), extra, rtol=1e-12)
        np.testing.assert_allclose(
            got[f"{q}_err"].sel(ball="softball"), np.hypot(plain[f"{q}_err"].sel(ball="softball"), extra), rtol=1e-12
        )
        np.testing.assert_array_equal(got[q], plain[q])  # values never move
        base = got.sel(ball="baseball")
        assert np.all((base[f"{q}_err_contact"] == 0) | np.isnan(base[f"{q}_err_contact"]))
        np.testing.assert_array_equal(base[f"{q}_err"], plain.sel(ball="baseball")[f"{q}_err"])
        if f"{q}_ci_high" in got:
            half = (got[f"{q}_ci_high"] - got[q]) / got[f"{q}_err"]
            np.testing.assert_allclose(half, (plain[f"{q}_ci_high"] - plain[q]) / plain[f"{q}_err"], rtol=1e-9)
    assert "e_x_err_contact" not in plain


def test_the_switch_turns_the_contact_error_off(config, balls, bats, monkeypatch):
    from helpers import NORM, REC

    from ballbat.stages import fit_ex, normalize, reconstruct, simulate
    from ballbat.synthetic import SyntheticSettings

    s = SyntheticSettings(**{**config["datasets"]["synthetic"]["synthetic"], "seed": 6})
    rec = reconstruct.run(REC, normalize.run(NORM, simulate.run(s, balls, bats)), balls, bats)
    settings = fit_ex.FitExSettings(mu_k_example=0.5, systematic=False, check_physical=True, mu_k_bound=True)
    monkeypatch.setattr(fitting, "CONTACT_POPULATION_ERROR", False)
    got = fit_ex.run(settings, _with_contact_shift(rec, 2e-3, "softball"))
    xr_equal = fit_ex.run(settings, rec)
    assert "e_x_err_contact" not in got
    np.testing.assert_array_equal(got["e_y_implied_err"], xr_equal["e_y_implied_err"])


def test_e_x_per_bat_error_is_the_sandwich_with_the_scatter_terms_weights(config, balls, bats, monkeypatch):
    """e_x per bat: the value as before, the error the HC3 sandwich of the same fit (``PER_BAT_SANDWICH``);
    the pooled fits do not change.
    """
    from helpers import NORM, REC

    from ballbat.columns import Columns
    from ballbat.designs import Measured, measured_sigma, spin_design
    from ballbat.linefit import eiv_line
    from ballbat.stages import normalize, reconstruct, simulate
    from ballbat.synthetic import SyntheticSettings

    syn = {**config["datasets"]["synthetic"]["synthetic"], "seed": 7, "e_x_scatter": 0.02}
    rec = reconstruct.run(REC, normalize.run(NORM, simulate.run(SyntheticSettings(**syn), balls, bats)), balls, bats)
    res = fitting.analyze_impacts(rec, 0.5, False)
    monkeypatch.setattr(fitting, "PER_BAT_SANDWICH", False)
    old = fitting.analyze_impacts(rec, 0.5, False)
    np.testing.assert_array_equal(res.e_x.field("slope"), old.e_x.field("slope"))
    np.testing.assert_array_equal(res.e_x_pooled.field("slope_err"), old.e_x_pooled.field("slope_err"))
    assert not np.allclose(res.e_x.field("slope_err"), old.e_x.field("slope_err"), equal_nan=True)
    ds = Columns(rec)
    sel = (ds["flag"].values == 0) & (ds["ball"].values == "softball") & (ds["bat"].values == "wood")
    r, r_x, alpha = (ds[k].values[sel] for k in ("r", "r_x", "alpha"))
    x, y, jx, jy = spin_design(Measured.from_dataset(ds, sel), r, r_x, alpha)
    want = eiv_line(x, y, jx, jy, measured_sigma(ds, sel), scatter=True, robust=True)
    got = res.e_x.fits[res.balls.index("softball"), res.bats.index("wood")]
    assert got.slope_err == pytest.approx(want.slope_err, rel=1e-12) and got.scatter == pytest.approx(want.scatter)


@pytest.mark.parametrize("scatter", [0.0, 0.02])
def test_the_values_alone_are_the_full_analysis_values_to_the_bit(config, balls, bats, scatter):
    """analyze_impacts(errors=False), which the refits call (issue 39): every value of fit_ex.nc's refitted
    quantities and every scatter tau equal the full analysis's bit for bit; the errors are NaN (not made).
    """
    from helpers import NORM, REC

    from ballbat.stages import fit_ex, normalize, reconstruct, simulate
    from ballbat.synthetic import SyntheticSettings
    from ballbat.systematics import FIT_QUANTITIES

    syn = {**config["datasets"]["synthetic"]["synthetic"], "seed": 8, "e_x_scatter": scatter}
    rec = reconstruct.run(REC, normalize.run(NORM, simulate.run(SyntheticSettings(**syn), balls, bats)), balls, bats)
    rec = rec.drop_vars([k for k in rec.data_vars if k.startswith("truth_")])
    full = fit_ex.results_values(fitting.analyze_impacts(rec, 0.5, False))
    alone = fit_ex.results_values(fitting.analyze_impacts(rec, 0.5, False, errors=False))
    for q in (*FIT_QUANTITIES, *(f"{f}_scatter" for f in fit_ex.SCATTER_FITS)):
        assert np.any(np.isfinite(full[q])), q
        np.testing.assert_array_equal(alone[q], full[q], err_msg=q)
    assert np.all(np.isnan(alone["e_x_err"])) and np.all(np.isnan(alone["e_y_implied_err"]))
    assert np.sum(np.isfinite(full["e_x_err"])) >= 7  # a bat without softball impacts has none
    np.testing.assert_array_equal(alone["e_x_status"], full["e_x_status"])
    if scatter:
        assert np.nanmax(full["e_x_scatter"]) > 0.005  # the scatter term was fitted
