"""The eta^2 fit of Stronge's model (ballbat.stronge.fit): recovery, robust intervals and degrees of freedom,
free mu, e_y absorbed, bad inputs named.
"""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.properties import recoil_factors
from ballbat.stronge.fit import Eta2FitError, fit_eta2
from ballbat.stronge.model import ContactParams, stronge_ex


# ------------------------------------------------------------------------------------------
# eta^2 fit
# ------------------------------------------------------------------------------------------
def _synthetic(balls, bats, rng, eta2=4.75, n=58, noise=0.01):
    ball = balls["baseball"]
    rr = np.array([recoil_factors(ball, bats[b]) for b in ("wood", "metal_rough", "metal_smooth")])
    k = rng.integers(0, 3, n)
    r_x, r_y = rr[k, 0], rr[k, 1]
    psi = rng.uniform(0, ball.psi_max, n)
    x = np.tan(psi) / (1 + r_x)
    y = (1 + stronge_ex(psi, ContactParams(eta2, 0.5, 0.5, r_x, r_y))) * x + rng.normal(0, noise, n)
    return psi, x, y, r_x, r_y


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fit_recovers_eta2(seed, balls, bats):
    """Synthetic Eq. (vtf) data at eta2 = 4.75 with noise: recovered within 3 standard errors,
    and the 95 % profile interval brackets the fit (its speed is bench/profile_study.py's, not a test's).
    """
    import lmfit  # noqa: F401  (import once, outside the timing)

    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(seed))
    f = fit_eta2(psi, x, y, r_x, r_y)
    assert f.success and f.n == 58 and f.nfree == 57
    assert abs(f.eta2 - 4.75) < 3 * f.eta2_err
    assert f.eta2_ci_low < f.eta2 < f.eta2_ci_high
    # scale_covar=True: the interval is +-1.96 SE for a nearly linear model
    assert (f.eta2_ci_high - f.eta2_ci_low) / 2 == pytest.approx(1.96 * f.eta2_err, rel=0.1)
    assert f.redchi == pytest.approx(0.01**2, rel=0.4)
    assert np.isnan(f.e_y_err) and f.e_y == 0.5
    # known sigma, unscaled covariance: same eta2, comparable error
    g = fit_eta2(psi, x, y, r_x, r_y, sigma=0.01, scale_covar=False)
    assert g.eta2 == pytest.approx(f.eta2, rel=1e-6)
    assert g.delta_chi2 == pytest.approx(3.841, abs=1e-3)


def test_robust_fit_interval_and_dof(balls, bats):
    """robust=True: same eta2; the interval is +-t_nu SE for a nearly linear model, with the
    Bell-McCaffrey nu below n - 1 (it counts how many impacts carry the fit).
    """
    from scipy import stats

    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(5))
    strata = np.where(r_x == r_x[0], "a", "b")
    f = fit_eta2(psi, x, y, r_x, r_y)
    g = fit_eta2(psi, x, y, r_x, r_y, robust=True, strata=strata)
    assert g.robust and not f.robust and f.dof == f.nfree
    assert g.eta2 == f.eta2
    assert 5 < g.dof < f.nfree
    tq = stats.t.ppf(0.975, g.dof)
    assert (g.eta2_ci_high - g.eta2_ci_low) / 2 == pytest.approx(tq * g.eta2_err, rel=0.1)
    assert g.eta2_err == pytest.approx(f.eta2_err, rel=0.5)  # same data, homoscedastic noise
    h = fit_eta2(psi, x, y, r_x, r_y, robust=True, strata=strata, interval=False)
    assert h.eta2 == g.eta2 and h.eta2_err == g.eta2_err and np.isnan(h.eta2_ci_low) and np.isnan(h.eta2_ci_high)
    with pytest.raises(ValueError, match="strata must have one label per impact"):
        fit_eta2(psi, x, y, r_x, r_y, robust=True, strata=strata[:-1])


@pytest.mark.slow  # seconds (quiet machine): more than a unit test may take
def test_robust_error_describes_repeats_of_a_design_with_fixed_bats(balls, bats):
    """Three bats of constant e_x 0.10, 0.17, 0.24 (Table II-like; one eta^2 cannot describe
    them), 15 impacts each at random psi, repeated 60 times: the spread of eta2 over the
    repeats is what the bat-stratified error reports (0.8-1.25), whereas the plain sandwich
    counts the bats' fixed misfit as scatter and overstates it (spread/SE below 0.85 of the
    stratified ratio).
    """
    ball = balls["softball"]
    names = ["wood", "metal_rough", "metal_smooth"]
    rr = np.array([recoil_factors(ball, bats[b]) for b in names])
    ex_bat = np.array([0.10, 0.17, 0.24])
    rng = np.random.default_rng(11)
    k = np.repeat([0, 1, 2], 15)
    r_x, r_y, labels = rr[k, 0], rr[k, 1], np.array(names)[k]
    fits = []
    for _ in range(60):
        psi = rng.uniform(0.05, ball.psi_max, k.size)
        x = np.tan(psi) / (1 + r_x)
        y = (1 + ex_bat[k]) * x + rng.normal(0, 0.01, k.size)
        a = fit_eta2(psi, x, y, r_x, r_y, robust=True, strata=labels)
        b = fit_eta2(psi, x, y, r_x, r_y, robust=True)
        fits.append((a.eta2, a.eta2_err, b.eta2_err))
    eta2, err_strat, err_plain = np.array(fits).T
    spread = eta2.std(ddof=1)
    assert 0.8 < spread / err_strat.mean() < 1.25
    assert spread / err_plain.mean() < 0.85 * spread / err_strat.mean()


def test_fit_with_free_mu(balls, bats):
    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(3))
    f = fit_eta2(psi, x, y, r_x, r_y, vary_mu=True)
    assert np.isfinite(f.mu_err) and abs(f.eta2 - 4.75) < 3 * f.eta2_err


def test_fit_absorbs_e_y(balls, bats, wood):
    """With e_y fixed at 0.4 or 0.6 instead of 0.5, the refitted eta2 moves (4.15 / 5.39 for
    exact baseball model data) but the fitted curve stays within 5e-3 rms of the data: the
    paper's 'insensitive' holds for the curves, not for eta2.
    """
    r_x, r_y = wood["baseball"]
    psi = np.linspace(0.01, balls["baseball"].psi_max, 60)
    x = np.tan(psi) / (1 + r_x)
    y = (1 + stronge_ex(psi, ContactParams(4.75, 0.5, 0.5, r_x, r_y))) * x
    for e_y, eta2 in ((0.4, 4.15), (0.6, 5.39)):
        f = fit_eta2(psi, x, y, r_x, r_y, e_y=e_y)
        assert f.eta2 == pytest.approx(eta2, abs=0.01)
        assert np.sqrt(f.chisqr / f.n) < 5e-3


def test_fit_input_errors(balls, bats):
    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(4), n=10)
    with pytest.raises(ValueError, match="same length"):
        fit_eta2(psi, x[:-1], y, r_x, r_y)
    y_bad = y.copy()
    y_bad[3] = np.nan
    with pytest.raises(ValueError, match=r"y has non-finite.*n=10 impacts"):
        fit_eta2(psi, x, y_bad, r_x, r_y)
    with pytest.raises(ValueError, match="need more than 3"):
        fit_eta2(psi[:3], x[:3], y[:3], r_x[:3], r_y[:3], vary_e_y=True, vary_mu=True)


@pytest.mark.parametrize(("success", "eta2"), [(False, 4.75), (True, np.nan)])
def test_failed_fit_names_its_inputs(balls, bats, monkeypatch, success, eta2):
    """A failure that lmfit reports (mu free), or a non-finite eta^2, is an Eta2FitError naming the fit's inputs."""
    import lmfit

    real = lmfit.minimize

    def failing(*args, **kwargs):
        res = real(*args, **kwargs)
        res.success, res.message = success, "the fit wandered off"
        res.params["eta2"].value = eta2
        return res

    monkeypatch.setattr(lmfit, "minimize", failing)
    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(4), n=10)
    lo, hi = np.degrees(psi.min()), np.degrees(psi.max())
    with pytest.raises(Eta2FitError) as info:
        fit_eta2(psi, x, y, r_x, r_y, e_y=0.4, vary_mu=True)
    assert str(info.value) == (
        f"fit_eta2: fit failed (the fit wandered off) (n=10 impacts, psi {lo:.3g}..{hi:.3g} deg,"
        " e_y=0.4 (fixed), mu=0.5 (free))"
    )
    assert isinstance(info.value, RuntimeError)  # callers that catch a failed fit as a RuntimeError still do


@pytest.mark.parametrize(
    ("ier", "best", "why"),
    [(5, 0.3, "fit failed (Too many function calls"), (1, np.nan, "the least-squares fit raised ValueError")],
)
def test_failed_fit_of_eta2_alone_names_its_inputs(balls, bats, monkeypatch, ier, best, why):
    """eta^2 alone (MINPACK without lmfit's Parameters): a failure MINPACK reports, or a non-finite
    internal value, is an Eta2FitError naming the fit's inputs.
    """
    import scipy.optimize

    real = scipy.optimize.leastsq

    def failing(fcn, x0, **kwargs):
        _, cov, info, _, _ = real(fcn, x0, **kwargs)
        return np.array([best]), cov, info, "wandered off", ier

    monkeypatch.setattr(scipy.optimize, "leastsq", failing)
    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(4), n=10)
    lo, hi = np.degrees(psi.min()), np.degrees(psi.max())
    with pytest.raises(Eta2FitError) as info:
        fit_eta2(psi, x, y, r_x, r_y, e_y=0.4)
    assert str(info.value).startswith(f"fit_eta2: {why}")
    assert str(info.value).endswith(f"(n=10 impacts, psi {lo:.3g}..{hi:.3g} deg, e_y=0.4 (fixed), mu=0.5 (fixed))")


def _via_lmfit(residual, start, bounds, scale_covar):
    """lmfit.minimize on eta^2 alone, as fit_eta2 called it before it fitted eta^2 alone itself."""
    import lmfit

    from ballbat.stronge.fit import _LeastSquares, _lmfit_errors

    params = lmfit.Parameters()
    params.add("eta2", value=start[0], min=bounds[0], max=bounds[1])
    params.add("e_y", value=start[1], min=0.05, max=1.0, vary=False)
    params.add("mu", value=start[2], min=1e-3, max=10.0, vary=False)
    res = lmfit.minimize(
        lambda p: residual(p["eta2"].value, p["e_y"].value, p["mu"].value),
        params,
        method="leastsq",
        scale_covar=scale_covar,
    )
    values = {k: res.params[k].value for k in ("eta2", "e_y", "mu")}
    errs = _lmfit_errors(res.params)
    return _LeastSquares(values, errs, ("eta2",), float(res.chisqr), int(res.nfree), res.success, str(res.message))


@pytest.mark.parametrize(("seed", "e_y", "mu"), [(0, 0.5, 0.5), (1, 0.4, 0.2), (2, 1.0, 1.5), (3, 0.5, 0.0)])
def test_eta2_alone_is_lmfits_fit_to_the_bit(balls, bats, monkeypatch, seed, e_y, mu):
    """With e_y and mu fixed, fit_eta2 computes lmfit's leastsq itself: every number of the result
    (value, standard errors, interval, chi^2, message; robust or not, scaled or not) equals the one
    lmfit gives, bit for bit (mu = 0 is clipped to lmfit's lower bound 1e-3 in both).
    """
    from ballbat.stronge import fit as fit_module

    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(seed), n=40)
    strata = np.repeat(["a", "b", "c", "d"], 10)
    for kw in ({}, {"scale_covar": False, "sigma": 0.01}, {"robust": True, "strata": strata}):
        ours = fit_eta2(psi, x, y, r_x, r_y, e_y=e_y, mu=mu, **kw)
        with monkeypatch.context() as m:
            m.setattr(fit_module, "_lm_eta2_alone", _via_lmfit)
            theirs = fit_eta2(psi, x, y, r_x, r_y, e_y=e_y, mu=mu, **kw)
        assert ours.message == theirs.message == "Fit succeeded."
        for name in ("eta2", "eta2_err", "eta2_ci_low", "eta2_ci_high", "chisqr", "redchi", "dof", "e_y", "mu"):
            np.testing.assert_equal(getattr(ours, name), getattr(theirs, name), err_msg=name)  # NaN == NaN


def test_the_residual_runs_the_model_once_per_point(balls, bats):
    """The fit's residual returns a point it has evaluated (scalar parameters equal to the bit) without
    running the model again, the same numbers; array parameters (the Jacobian's steps) always run it.
    """
    from ballbat.stronge.fit import _Residual
    from ballbat.stronge.model import ImpactGeometry

    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(5), n=20)
    res = _Residual(ImpactGeometry(psi, r_x, r_y, 0.4), x, y, np.ones_like(x))
    a = res(4.75, 0.5, 0.5)
    a[0] = np.nan  # the caller's copy: what the residual keeps stays as computed
    b = res(4.75, 0.5, 0.5)
    assert res.calls == 1
    np.testing.assert_array_equal(b, (y - (1 + stronge_ex(psi, ContactParams(4.75, 0.5, 0.5, r_x, r_y))) * x))
    res(np.array([[4.75]]), 0.5, 0.5)
    res(4.750000000000001, 0.5, 0.5)
    assert res.calls == 3


def test_value_alone_without_errors(balls, bats):
    """errors=False (a study's noise-free truth): the same value and chi^2, the errors and dof NaN;
    the profile interval needs the errors, and asking for both is a ValueError.
    """
    from ballbat.stronge.analysis import VtfData, fit_ball

    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(6), n=30)
    bats_of = np.repeat(["a", "b", "c"], 10)
    data = VtfData(psi, x, y, np.full(30, 0.01), r_x, r_y, np.full(30, 0.4), bats_of)
    full = fit_ball(data, e_y=0.5, mu=0.5, vary_e_y=False, vary_mu=False, interval=False)
    alone = fit_ball(data, e_y=0.5, mu=0.5, vary_e_y=False, vary_mu=False, interval=False, errors=False)
    assert (alone.eta2, alone.chisqr) == (full.eta2, full.chisqr)
    assert np.isfinite(full.eta2_err) and np.isnan(alone.eta2_err) and np.isnan(alone.dof)
    with pytest.raises(ValueError, match="the profile interval needs the standard errors"):
        fit_eta2(psi, x, y, r_x, r_y, errors=False)


def test_the_start_snapped_to_zero_below_lmfits_own_tiny():
    """fit.LMFIT_TINY is lmfit's ``lineshapes.tiny``, which lmfit's leastsq wrapper compares the start with."""
    from lmfit.lineshapes import tiny

    from ballbat.stronge import fit

    assert fit.LMFIT_TINY == tiny


@pytest.mark.parametrize("eta2", [2.5, 4.75, 12.0])
def test_a_fit_started_next_to_its_minimum_is_the_scans_fit(balls, bats, eta2, monkeypatch):
    """``start`` (the calibration refits start at the nominal fit, issue 39): from the scan's fit moved by 1 % the
    least squares end within 1e-7 of the scan's fit (Levenberg-Marquardt's tolerance), and skip the scan; a start
    outside the bounds or NaN is the scan's own, to the bit.
    """
    from ballbat.stronge import fit as fit_module

    psi, x, y, r_x, r_y = _synthetic(balls, bats, np.random.default_rng(3), eta2=eta2, n=80)
    scanned = fit_eta2(psi, x, y, r_x, r_y, interval=False)
    calls = []
    real = fit_module._scan_start
    monkeypatch.setattr(fit_module, "_scan_start", lambda *a: calls.append(1) or real(*a))
    for factor in (1.01, 0.99):
        near = fit_eta2(psi, x, y, r_x, r_y, interval=False, start=scanned.eta2 * factor)
        assert near.eta2 == pytest.approx(scanned.eta2, rel=1e-7)
        assert near.eta2_err == pytest.approx(scanned.eta2_err, rel=1e-5)
    assert calls == []
    for bad in (np.nan, 0.5, 31.0):
        again = fit_eta2(psi, x, y, r_x, r_y, interval=False, start=bad)
        assert again.eta2 == scanned.eta2 and again.eta2_err == scanned.eta2_err
    assert len(calls) == 3


def test_the_two_pass_scan_starts_where_the_whole_scan_does(balls, bats, monkeypatch):
    """150 fits (eta^2 1.5-25, 20-200 impacts, noise 0.003-0.03), some with two minima of chi^2 over the scan: the
    scan in two passes (every third value, then around each of its local minima) starts every fit at the whole
    scan's lowest chi^2, so the fit is the same to the bit (refined around the lowest coarse value alone, one of
    them stopped in the other minimum).
    """
    from ballbat.stronge import fit as fit_module
    from ballbat.stronge.model import ImpactGeometry

    rng = np.random.default_rng(12)
    two_minima = 0
    for k in range(150):
        eta2, n = float(np.exp(rng.uniform(np.log(1.5), np.log(25)))), int(rng.integers(20, 200))
        noise = float(rng.choice([0.003, 0.01, 0.03]))
        psi, x, y, r_x, r_y = _synthetic(balls, bats, rng, eta2=eta2, n=n, noise=noise)
        with monkeypatch.context() as m:
            m.setattr(fit_module, "SCAN_STRIDE", 1)
            whole = fit_eta2(psi, x, y, r_x, r_y, interval=False)
        two = fit_eta2(psi, x, y, r_x, r_y, interval=False)
        assert two.eta2 == whole.eta2 and two.eta2_err == whole.eta2_err, (k, eta2, n)
        c = fit_module._chi2_at(ImpactGeometry(psi, r_x, r_y), x, y, np.ones(n), 0.5, 0.5, np.geomspace(1, 30, 48))
        two_minima += np.sum((c[1:-1] < c[:-2]) & (c[1:-1] < c[2:])) >= 2
    assert two_minima >= 3, two_minima
