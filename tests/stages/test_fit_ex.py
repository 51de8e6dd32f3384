"""The fit_ex stage (ballbat.stages.fit_ex): e_x recovered from synthetic data with honest standard errors,
the intrinsic-scatter term declared, the stage giving the compute functions' numbers (Sec. IV; issue 36).
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import fit_chain as run

from ballbat import fitting
from ballbat.stages import fit_ex, reconstruct
from ballbat.stages.fit_ex import fit_ex_table
from workflow_helpers import ROOT


def test_recovery_default_config(default_settings, balls, bats):
    """Issue 2: pooled e_x within 2 SE of the truth, each bat x ball within 3 SE."""
    fit = run(default_settings, balls, bats)
    for ball in fit.ball.values:
        f = fit.sel(ball=ball)
        assert abs(f.e_x_pooled - f.truth_e_x_pooled) < 2 * f.e_x_pooled_err, ball
        for bat in fit.bat.values:
            g = f.sel(bat=bat)
            if int(g.e_x_n) == 0:
                continue
            assert abs(g.e_x - g.truth_e_x) < 3 * g.e_x_err, (ball, bat)
            assert g.e_x_ci_low < g.e_x < g.e_x_ci_high
    # Per-bat truth is exactly the configured Table II value (no intrinsic scatter).
    assert float(fit.truth_e_x.sel(ball="baseball", bat="wood")) == pytest.approx(0.464, rel=1e-12)
    assert int(fit.e_x_n.sel(ball="baseball", bat="softball_composite")) == 0  # no baseball on it


@pytest.mark.slow  # about 2 s: 60 experiments
def test_standard_errors_are_honest(default_settings, balls, bats):
    """Coverage: over 60 seeds the pooled e_x lies within 2 SE of the truth ~95 % of the time."""
    hits, pulls = 0, []
    for seed in range(60):
        fit = run(default_settings, balls, bats, seed=1000 + seed)
        f = fit.sel(ball="baseball")
        pull = float((f.e_x_pooled - f.truth_e_x_pooled) / f.e_x_pooled_err)
        pulls.append(pull)
        hits += abs(pull) < 2
    assert hits / 60 >= 0.85  # binomial: 95 % expected, 0.85 is ~3.5 sigma below
    assert abs(np.mean(pulls)) < 0.5  # no bias larger than half a standard error
    assert 0.7 < np.std(pulls) < 1.4


def test_truth_of_ratio_and_e_y(default_settings, balls, bats):
    fit = run(default_settings, balls, bats)
    for ball, e_y in (("baseball", 0.45), ("softball", 0.32)):
        f = fit.sel(ball=ball)
        assert float(f.truth_e_y_implied) == pytest.approx(e_y)
        assert abs(f.e_y_implied - e_y) < 3 * f.e_y_implied_err
        assert abs(f.tan_ratio_slope - f.truth_tan_ratio_slope) < 3 * f.tan_ratio_slope_err


@pytest.mark.parametrize(
    "fit, dims", [("e_x", ("ball", "bat")), ("e_x_pooled", ("ball",)), ("tan_ratio_slope", ("ball",))]
)
def test_fit_ex_declares_the_scatter_with_units_and_words(fit, dims):
    table = fit_ex_table(False, 0.5)
    for name in (f"{fit}_scatter", f"{fit}_scatter_ci_low", f"{fit}_scatter_ci_high"):
        assert table[name].units == "1"
        assert table[name].dims == dims
        assert f"{fit}_scatter" in table[name].long_name or "tau" in table[name].long_name


def test_the_pooled_fits_report_the_scatter_within_bats(default_settings, balls, bats):
    """The pooled e_x and the Eq. ratio slope carry a scatter term estimated within bats, with its interval.

    Drawn with e_x scattering by 0.03 from impact to impact, the pooled e_x's interval of tau holds
    0.03 (the bats' own e_x differ by up to 0.11, which is not scatter), and the Eq. ratio slope's
    tau is positive (its scatter is e_x's, scaled by the recoil factors); drawn without, both
    intervals reach down to 0.
    """
    impacts = {ball: {bat: 5 * n for bat, n in per.items()} for ball, per in default_settings["impacts"].items()}
    fit = run(default_settings, balls, bats, e_x_scatter=0.03, impacts=impacts)
    pooled, ratio = fit["e_x_pooled_scatter_ci_low"].values, fit["tan_ratio_slope_scatter_ci_low"].values
    assert np.all(pooled < 0.03) and np.all(fit["e_x_pooled_scatter_ci_high"].values > 0.03)
    assert np.all(ratio > 0.0)
    plain = run(default_settings, balls, bats)
    for name in ("e_x_pooled", "tan_ratio_slope"):
        tau, lo, hi = (plain[f"{name}_scatter{k}"].values for k in ("", "_ci_low", "_ci_high"))
        assert np.all(lo == 0.0) and np.all(tau <= hi) and np.all(hi > 0.0), name


# ---------------------------------------------------------------------------------------
# the stages give the compute functions' numbers


def test_fit_ex_stage_gives_the_compute_functions_numbers(chain, config):
    """fit_ex.run on a tiny reduced set: its values are those of fitting.analyze_impacts, nothing lost or added."""
    rec = chain["red_rec"]
    res = fitting.with_contact_error(rec, fitting.analyze_impacts(rec, 0.5))
    assert res.contact_error is not None  # reduced tracks: the contact population's error is carried
    fit = fit_ex.run(fit_ex.FitExSettings.from_config(config), rec)
    np.testing.assert_array_equal(fit["e_y_implied_err"].values, res.per_ball["e_y_implied_err"])
    np.testing.assert_array_equal(fit["e_x_err_contact"].values, res.contact_error["e_x"])
    np.testing.assert_array_equal(fit["e_x"].values, res.e_x.field("slope", -1.0))
    np.testing.assert_array_equal(fit["e_x_err"].values, res.e_x.field("slope_err"))
    np.testing.assert_array_equal(fit["e_x_pooled"].values, res.e_x_pooled.field("slope", -1.0))
    np.testing.assert_array_equal(fit["tan_ratio_slope"].values, res.tan_ratio_slope.field("slope"))
    np.testing.assert_array_equal(fit["e_y_implied"].values, res.per_ball["e_y_implied"])
    np.testing.assert_array_equal(fit["e_x_err_scale"].values, res.systematic["e_x_err_scale"])
    assert list(fit["ball"].values) == res.balls and list(fit["bat"].values) == res.bats
    assert np.isfinite(fit["e_x_pooled"].values).all()
    assert fit.attrs["n_impacts"] == rec.sizes["impact"]
    assert fit.attrs["n_excluded"] == int((rec["flag"].values != 0).sum())
    assert fit.attrs["v_ref"] == rec.attrs["v_ref"] and fit.attrs["mu_k_example"] == 0.5
    # without the systematic (the studies): no *_err_scale, the same fits
    quiet = fit_ex.run(fit_ex.FitExSettings(0.5, systematic=False, check_physical=True, mu_k_bound=True), rec)
    assert "e_x_err_scale" not in quiet
    np.testing.assert_array_equal(quiet["e_x"].values, fit["e_x"].values)


def test_fit_ex_stage_refuses_an_impossible_e_x_unless_told(chain):
    """Spin of the wrong sign gives e_x < -1: an error of the dataset; the studies record it as it comes."""
    flipped = chain["norm"].copy()
    flipped["omega"] = -flipped["omega"]
    rec = reconstruct.run(reconstruct.ReconstructSettings(), flipped, *_tables())
    with pytest.raises(fitting.ImplausibleFit, match="outside the physical range"):
        fit_ex.run(fit_ex.FitExSettings(0.5, systematic=False, check_physical=True, mu_k_bound=True), rec)
    fit = fit_ex.run(fit_ex.FitExSettings(0.5, systematic=False, check_physical=False, mu_k_bound=True), rec)
    assert np.nanmin(fit["e_x_pooled"].values) < -1


def _tables():
    from ballbat.properties import load_balls, load_bats

    return load_balls(ROOT / "config" / "balls.csv"), load_bats(ROOT / "config" / "bats.csv")
