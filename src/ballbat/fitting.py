"""Sec. IV of one dataset: e_x per bat and ball (Eq. omega), Eq. ratio, Eq. muk and Figs. 3-4 slopes.

:func:`analyze_impacts` computes (a :class:`Sec4` of arrays and line fits); the stage
:mod:`ballbat.stages.fit_ex` declares the fit_ex.nc file and assembles it. Every fit is a
straight line fitted with lmfit (:mod:`ballbat.linefit`) on a design of :mod:`ballbat.designs`.
Measurement uncertainties enter through the *effective variance* of each impact's residual:
the abscissa and the ordinate are both functions of the measured (v_bat, v_ball, theta,
omega), so the residual
y - (a + s x) has variance sum_k (dy/dm_k - s dx/dm_k)^2 sigma_k^2 over the measured
quantities m_k (correlations between x and y through psi included). The weights depend
on the slope, so the fit is iterated (three passes converge to far below the standard
error). Standard errors come from the scatter of the data (as the paper's do): Eq. ratio's
is lmfit's, scaled by the reduced chi-square, e_x's per bat and pooled HC3 sandwiches with the
intrinsic-scatter term's weights (:data:`PER_BAT_SANDWICH`, :data:`POOLED_SANDWICH`); the
reduced chi-square itself tells whether the stated measurement uncertainties explain that
scatter. Each quantity that pools impacts also carries the error of the contact-time
population its impacts share (:func:`with_contact_error`). The Figs. 3-4 lines summarise data the
model does not describe impact by impact (bats of different e_x, spin and speed not exactly
linear in theta): their scatter is not the same everywhere, and their standard errors are
the sandwich (HC3) ones, which the replicate studies (:mod:`ballbat.studies`) find
calibrated where the scaled covariance was 10-20 % small. e_y implied by Eq. ratio inverts
the slope with each impact's recoil factors and its bat's e_x, weighted as the fit weighs the
impacts (:func:`implied_e_y`), with a sandwich standard error. Every abscissa is measured,
so every fit is corrected for its noise (errors in variables: the moment-corrected fit
:func:`ballbat.linefit.eiv_line`, which the replicate studies find unbiased where plain least
squares was attenuated by up to 0.8 standard errors: docs/studies.md). 95 % intervals use Student's t with
n - p degrees of freedom. Without uncertainties the fit is unweighted and the
reduced chi-square is undefined (NaN).

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017), Sec. IV.
.. [2] J. Orear, "Least squares when both variables have uncertainties",
   Am. J. Phys. 50, 912 (1982) (effective variance).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from . import linefit
from .columns import Columns
from .designs import MEASURED, Measured, measured_sigma, normalized_theta_design, spin_design, tan_ratio_design
from .kinematics import gross_slip_onset, normalize_to_bat_speed, tan_ratio_slope_model
from .linefit import MIN_FIT_IMPACTS, LineFit, fit_line, scatter_gain, wls_slope
from .systematics import SIDES, contact_shifted_impacts, has_contact_shifts, has_shifts

if TYPE_CHECKING:
    import xarray as xr
    from numpy.typing import ArrayLike


class FitStatus(enum.IntEnum):
    """Why a fit of e_x has no value (``e_x_status``, ``e_x_pooled_status``)."""

    OK = 0
    NO_IMPACTS = 1
    TOO_FEW_IMPACTS = 2
    FIT_FAILED = 3


def fit_status(fit: LineFit) -> FitStatus:
    """Return the :class:`FitStatus` of a fit of e_x."""
    if fit.n == 0:
        return FitStatus.NO_IMPACTS
    if fit.n < MIN_FIT_IMPACTS:
        return FitStatus.TOO_FEW_IMPACTS
    return FitStatus.OK if fit.success else FitStatus.FIT_FAILED


@dataclass
class FitGrid:
    """Line fits on a grid of labels (ball, or ball x bat), with the truth of each (NaN if none)."""

    fits: np.ndarray  # object array of LineFit
    truth: np.ndarray  # float

    @classmethod
    def empty(cls, shape: tuple[int, ...]) -> FitGrid:
        """Return a grid of fits not made (no impacts)."""
        fits = np.empty(shape, dtype=object)
        for idx in np.ndindex(shape):
            fits[idx] = LineFit.not_fitted(0)
        return cls(fits, np.full(shape, np.nan))

    def field(self, name: str, offset: float = 0.0) -> np.ndarray:
        """One field of every fit (``slope``, ``slope_err``...), plus ``offset``."""
        return np.vectorize(lambda f: getattr(f, name), otypes=[float])(self.fits) + offset


@dataclass
class Sec4:
    """The Sec. IV results of one dataset (dims: ball, or ball x bat)."""

    balls: list[str]
    bats: list[str]
    has_truth: bool
    mu_k_example: float
    e_x: FitGrid  # Eq. omega per bat: the slope is 1 + e_x
    e_x_pooled: FitGrid
    tan_ratio_slope: FitGrid
    spin_theta_slope: FitGrid
    speed_theta_slope: FitGrid
    per_ball: dict[str, np.ndarray] = field(default_factory=dict)
    systematic: dict[str, np.ndarray] | None = None  # pixel-scale systematic of e_x (scale_systematic)
    systematics: object = None  # every calibration source to every quantity (ballbat.systematics)
    #: Per quantity of :data:`CONTACT_QUANTITIES`, its error from the contact population's estimate
    #: (:func:`contact_population_error`; included in the statistical errors), None where not carried.
    contact_error: dict[str, np.ndarray] | None = None


#: The pooled e_x and the Eq. ratio slope of a ball carry the intrinsic scatter within its bats
#: (``linefit.eiv_line`` with the bats as strata; docs/model.md). False: fitted without the term,
#: as before issue 36's last step (the studies' comparison, bench/intervals_study.py).
WITHIN_BAT_SCATTER = True
#: The pooled e_x's standard error is the HC3 sandwich centred within bats (the bats' own e_x differ
#: by design, not by chance), not the covariance scaled by the reduced chi-square, which counts
#: those differences as noise (with the scatter term it covered 97-98 %; docs/model.md). False:
#: the scaled covariance (bench/intervals_study.py's comparison).
POOLED_SANDWICH = True

#: e_x per bat's standard error is the HC3 sandwich (with the intrinsic-scatter term's weights), not the
#: covariance scaled by the reduced chi-square: with tau estimated from a bat's few impacts the weights
#: are themselves uncertain, and the sandwich does not rest on them (softballs on metal_smooth, 12
#: impacts, e_x scatter 0.02: 88.3 -> 92.3 %; docs/model.md). Only where the fit carries the term
#: (:data:`ballbat.linefit.SCATTER_TERM`). False: the scaled covariance (bench/intervals_study.py).
PER_BAT_SANDWICH = True

#: Per-ball quantities that are not line fits (values of :attr:`Sec4.per_ball`).
PER_BALL = (
    "e_y_implied",
    "e_y_implied_err",
    "truth_e_y_implied",
    "mu_k_lower_bound",
    "mu_k_lower_bound_err",
    "mu_k_lower_bound_impact",
    "truth_mu_k_lower_bound",
    "gross_slip_psi",
    "gross_slip_theta",
    "gross_slip_omega",
)


def _weights(jx, jy, sigma, slope, fit=None, x=None):
    if sigma is None or not np.isfinite(slope):
        return None
    var = np.sum((jy - slope * jx) ** 2 * sigma**2, axis=1)
    if fit is not None and np.isfinite(fit.scatter) and fit.scatter > 0:  # the fit's intrinsic-scatter term
        var = var + fit.scatter**2 * scatter_gain(x, np.sum(jx**2 * sigma**2, axis=1))
    return 1.0 / np.sqrt(var) if np.all(var > 0) else None


def _noise_moments(jx, jy, sigma) -> tuple[np.ndarray, np.ndarray]:
    """Each impact's noise variance of x and covariance of the x and y noise (zeros without uncertainties)."""
    if sigma is None:
        return np.zeros(len(jx)), np.zeros(len(jx))
    return np.sum(jx**2 * sigma**2, axis=1), np.sum(jx * jy * sigma**2, axis=1)


def fit_e_x(
    ds: xr.Dataset, balls: list[str], bats: list[str], with_truth: bool, errors: bool = True
) -> tuple[FitGrid, FitGrid]:
    """Fit Eq. omega per bat and ball and pooled per ball (usable impacts, ``flag == 0``).

    Parameters
    ----------
    ds : xarray.Dataset
        Reconstructed impacts.
    balls, bats : list of str
        The grid's labels.
    with_truth : bool
        Also apply the estimator to the noise-free ``truth_*`` (same weights).
    errors : bool
        False: the values alone (:func:`ballbat.linefit.eiv_line`'s ``errors``).

    Returns
    -------
    (FitGrid, FitGrid)
        Per bat and ball (ball x bat; the slope is 1 + e_x), pooled per ball.
    """
    ds = Columns(ds)
    usable = ds["flag"].values == 0
    ball_of = ds["ball"].values.astype(str)
    bat_of = ds["bat"].values.astype(str)
    per_bat, pooled = FitGrid.empty((len(balls), len(bats))), FitGrid.empty((len(balls),))

    def spin_fit(sel, strata=None):
        n = int(np.sum(sel))
        if n < MIN_FIT_IMPACTS:  # too few for a slope and its error: report, do not fit
            return LineFit.not_fitted(n), np.nan
        r, r_x, alpha = (ds[k].values[sel] for k in ("r", "r_x", "alpha"))
        x, y, jx, jy = spin_design(Measured.from_dataset(ds, sel), r, r_x, alpha)
        sig = measured_sigma(ds, sel)
        fit = fit_line(
            x,
            y,
            jx,
            jy,
            sig,
            errors_in_variables=True,
            strata=strata,
            scatter=strata is None or WITHIN_BAT_SCATTER,
            robust=POOLED_SANDWICH if strata is not None else PER_BAT_SANDWICH and linefit.SCATTER_TERM,
            errors=errors,
        )
        t = np.nan
        if with_truth and fit.success:
            xt, yt, _, _ = spin_design(Measured.from_dataset(ds, sel, "truth_"), r, r_x, alpha)
            t = wls_slope(xt, yt, _weights(jx, jy, sig, fit.slope, fit, x))[0] - 1.0
        return fit, t

    for i, ball in enumerate(balls):
        in_ball = usable & (ball_of == ball)
        for bat in sorted(set(bat_of[ball_of == ball])):
            j = bats.index(bat)
            per_bat.fits[i, j], per_bat.truth[i, j] = spin_fit(in_ball & (bat_of == bat))
        # pooled: the bats' differences are the design's (the same bats in every repetition), not
        # scatter; the intrinsic scatter is the one within bats (linefit.eiv_line with strata)
        pooled.fits[i], pooled.truth[i] = spin_fit(in_ball, bat_of[in_ball])
    return per_bat, pooled


#: Per-impact systematic uncertainties of the speeds from a camera's pixel scale (reduce.nc).
SCALE_VARS = ("v_bat_err_scale", "v_ball_err_scale")


def scale_systematic(ds: xr.Dataset, res: Sec4) -> dict[str, np.ndarray] | None:
    """Systematic error of e_x from the swing camera's pixel-scale uncertainty.

    The pixel scale is shared by every impact of a camera, so its uncertainty does not
    average out: every v_bat and v_ball is scaled by (1 +- its relative uncertainty) at once
    and e_x refitted; half the difference of the two fits is the systematic error. It is
    reported beside the statistical error, never added into it.

    Parameters
    ----------
    ds : xarray.Dataset
        Reconstructed impacts with ``v_bat_err_scale`` and ``v_ball_err_scale`` (datasets
        reduced from camera tracks).
    res : Sec4
        The fits of ``ds`` (for its labels).

    Returns
    -------
    dict or None
        ``e_x_err_scale`` (ball x bat) and ``e_x_pooled_err_scale`` (ball); None when the
        dataset has no pixel-scale uncertainty.
    """
    ds = Columns(ds)
    if not all(k in ds for k in SCALE_VARS):
        return None
    fits = []
    for sign in (1.0, -1.0):
        scaled = {}
        for k in ("v_bat", "v_ball"):
            rel = np.divide(ds[f"{k}_err_scale"].values, np.abs(ds[k].values))
            scaled[k] = ds[k] * (1.0 + sign * np.nan_to_num(rel))
        scaled = Columns(ds, scaled)
        fits.append(fit_e_x(scaled, res.balls, res.bats, with_truth=False))
    return {
        "e_x_err_scale": 0.5 * np.abs(fits[0][0].field("slope") - fits[1][0].field("slope")),
        "e_x_pooled_err_scale": 0.5 * np.abs(fits[0][1].field("slope") - fits[1][1].field("slope")),
    }


def implied_e_y(
    ds: xr.Dataset, sel: np.ndarray, res: Sec4, i: int, ratio_design: tuple, rfit: LineFit, errors: bool = True
) -> tuple[float, float]:
    """Return e_y implied by the Eq. ratio slope of one ball, and its standard error.

    Eq. ratio holds impact by impact: tan(psi - theta) = c_i (1 + e_x) / (1 + e_y) tan psi,
    with c_i = alpha/(1 + alpha) (1 + r_y)/(1 + r_x) of the impact's bat and ball and e_x of
    its bat. The fitted slope is the weighted mean of the impacts' slopes, so it is inverted
    with the same weighted mean of c_i (1 + e_x): 1 + e_y = sum(W x^2 c_i (1 + e_x,bat(i)))
    / sum(W x y), with the fit's weights W. (Inverting with the mean recoil factors
    and the pooled e_x instead, as a first version did, is biased by 0.3-0.6 of its error once
    the weights differ between bats: found by the replicate studies, docs/studies.md.)

    The standard error comes from the impacts' influences on ln(1 + e_y): through the e_x fit
    of the impact's bat and through sum(W x y), each impact about its own slope (the bats'
    differences are structure, not scatter; the same spin measurement enters both), a
    sandwich estimate with n / (n - k) for the k fitted slopes (its interval: Student's t with
    n - k degrees of freedom). Both sums are moment-corrected for the noise of the abscissa
    as the fits are (:func:`ballbat.linefit.eiv_line`): sum(W (x^2 - var x_i) c_i (1 + e_x))
    / sum(W (x y - cov(x_i, y_i))).

    Parameters
    ----------
    ds : xarray.Dataset
        Reconstructed impacts.
    sel : ndarray of bool
        The ball's usable impacts.
    res : Sec4
        The fits so far (e_x per bat and pooled).
    i : int
        The ball's index in ``res.balls``.
    ratio_design : tuple
        ``(x, y, jx, jy, sigma)`` of the Eq. ratio fit.
    rfit : LineFit
        The Eq. ratio fit.
    errors : bool
        False: the value alone (the error NaN), the same number to the bit.

    Returns
    -------
    (float, float)
    """
    x, y, jx, jy, sig = ratio_design
    ds = Columns(ds)
    r, r_x, r_y, alpha = (ds[k].values[sel] for k in ("r", "r_x", "r_y", "alpha"))
    bat_of = ds["bat"].values.astype(str)[sel]
    n = x.size
    w_r = _weights(jx, jy, sig, rfit.slope, rfit, x)  # the fit's weights, its scatter term included
    W = np.ones(n) if w_r is None else w_r**2
    # the noise of each abscissa (and its covariance with the ordinate), removed from the sums
    # as the moment-corrected fits remove it (linefit.eiv_line); zero without uncertainties
    var_x, cov_xy = _noise_moments(jx, jy, sig)
    if errors:  # each impact's e_x fit's design, for its influence
        xs, ys, jxs, jys = spin_design(Measured.from_dataset(ds, sel), r, r_x, alpha)
        var_xs, cov_s = _noise_moments(jxs, jys, sig)
    # each impact's e_x (its bat's; the pooled one where the bat has no fit) and its influence
    one_plus = np.empty(n)
    influence_ex = np.empty(n)
    lev_ex = np.zeros(n)
    groups = []
    for bat in sorted(set(bat_of)):
        m = bat_of == bat
        fit, m_fit = res.e_x.fits[i, res.bats.index(bat)], m
        if not (fit.success and np.isfinite(fit.slope)):  # no fit of its own: the pooled one
            fit, m_fit = res.e_x_pooled.fits[i], np.ones(n, dtype=bool)
        if not errors:
            one_plus[m] = fit.slope
            continue
        w = _weights(jxs[m_fit], jys[m_fit], None if sig is None else sig[m_fit], fit.slope, fit, xs[m_fit])
        ws = np.ones(int(m_fit.sum())) if w is None else w**2
        # the e_x fit's estimating function (moment-corrected for the bracket's noise, as the fit)
        score = xs[m_fit] * (ys[m_fit] - fit.slope * xs[m_fit]) + fit.slope * var_xs[m_fit] - cov_s[m_fit]
        infl = np.zeros(n)
        infl[m_fit] = ws * score / np.sum(ws * (xs[m_fit] ** 2 - var_xs[m_fit]))
        lev = np.zeros(n)
        lev[m_fit] = ws * xs[m_fit] ** 2 / np.sum(ws * xs[m_fit] ** 2)
        one_plus[m], influence_ex[m], lev_ex[m] = fit.slope, infl[m], lev[m]
        groups.append(m)
    # each impact's Eq. ratio slope times (1 + e_y): its recoil factors and its bat's e_x
    k_i = tan_ratio_slope_model(one_plus - 1.0, 0.0, r_x, r_y, alpha)
    # 1 + e_y = D / T with D = sum(W (x^2 - var x) k_i) and T = sum(W (x y - cov(x, y)))
    # (= slope sum(W (x^2 - var x)))
    x2 = x * x - var_x
    d = float(np.sum(W * x2 * k_i))
    t = float(np.sum(W * (x * y - cov_xy)))
    e_y = d / t - 1.0
    if not errors:
        return float(e_y), np.nan
    # influences on ln D (through each bat's e_x) and on ln T (each impact about its own
    # slope k_i / (1 + e_y): the bats' differences are structure, not scatter)
    share = np.zeros(n)
    for m in groups:
        share[m] = np.sum((W * x2 * k_i / one_plus)[m])
    infl_t = W * (x * y - cov_xy - k_i / (1.0 + e_y) * x2)
    lev_t = W * x * x / np.sum(W * x * x)
    var = e_y_variance(share * influence_ex / d, infl_t / t, lev_ex, lev_t, len(groups) + 1)
    return float(e_y), float((1.0 + e_y) * np.sqrt(var))


#: The form of implied e_y's sandwich (:func:`e_y_variance`): ``"hc3"``, ``"hc2"`` or ``"hc0k"``.
E_Y_SANDWICH = "hc2"


def e_y_variance(
    infl_ex: np.ndarray, infl_t: np.ndarray, lev_ex: np.ndarray, lev_t: np.ndarray, k: int, form: str | None = None
) -> float:
    """Variance of ln(1 + e_y) from the impacts' influences through e_x and through the Eq. ratio sum.

    Parameters
    ----------
    infl_ex, infl_t : ndarray
        Each impact's influence on ln D (through its bat's e_x fit) and on ln T (the Eq. ratio sum).
    lev_ex, lev_t : ndarray
        Each impact's leverage in its bat's e_x fit and in the Eq. ratio fit (in [0, 1)).
    k : int
        Slopes fitted (bats + 1).
    form : str, optional
        ``"hc0k"``: the plain sandwich with n / (n - k) (the first version); ``"hc2"``: each part
        divided by sqrt(1 - h) of its own fit; ``"hc3"``: by 1 - h (the delete-one jackknife to
        first order). Default :data:`E_Y_SANDWICH`.

    Returns
    -------
    float
    """
    form = E_Y_SANDWICH if form is None else form
    n = infl_ex.size
    if form == "hc0k":
        return float(np.sum((infl_ex - infl_t) ** 2) * n / max(n - k, 1))
    power = {"hc2": 0.5, "hc3": 1.0}.get(form)
    if power is None:
        raise ValueError(f"e_y_variance: form must be 'hc0k', 'hc2' or 'hc3', not {form!r}")
    keep = np.clip(1.0 - lev_ex, 1e-6, None) ** power, np.clip(1.0 - lev_t, 1e-6, None) ** power
    return float(np.sum((infl_ex / keep[0] - infl_t / keep[1]) ** 2))


#: Points of the grid on which :func:`largest_value` integrates the distribution of the largest value.
LARGEST_GRID = 4001

#: z beyond which ``scipy.special.log_ndtr(z)`` is below 7.7e-24 in magnitude (tests/test_fitting.py checks):
#: :func:`_log_cdf` leaves those terms out. A grid point's sum of them, over even 10^4 values, is below
#: 1e-19, under a thousandth of the last bit of exp(sum) near 1 (1.1e-16) and under half the last bit of
#: the sum where the sum is not tiny itself: the distribution function's bits do not move but by chance
#: (on 3000 random sets of 1-400 values, one grid point of 12 million moved by its last bit; round-off).
#: It was 40 (log_ndtr exactly -0.0), which evaluated 3-5x more of the grid (issue 39).
LOG_NDTR_NEGLIGIBLE = 10.0


#: Above this many values :func:`_log_cdf` works through the grid in blocks (bounded memory).
LARGEST_BY_IMPACT = 2000


def _log_cdf(m: np.ndarray, y: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """sum_i log Phi((m - y_i) / sigma_i) at every grid point ``m``: the log of :func:`largest_value`'s F.

    log Phi is negligible from z = 10 on (:data:`LOG_NDTR_NEGLIGIBLE`), which is most of the
    grid x values; only the rest is evaluated, and each grid point's sum runs over a C-ordered
    row of all the values as the full (grid, value) array's did: the same bits. Up to
    :data:`LARGEST_BY_IMPACT` values, each value's run of grid points (from the start) is
    evaluated; beyond, blocks of grid points with the points that matter picked out.
    """
    from scipy.special import log_ndtr

    if y.size <= LARGEST_BY_IMPACT:
        logs = np.full((y.size, m.size), -0.0)
        for i, end in enumerate(np.searchsorted(m, y + LOG_NDTR_NEGLIGIBLE * sigma)):
            logs[i, :end] = log_ndtr((m[:end] - y[i]) / sigma[i])
        return np.sum(np.ascontiguousarray(logs.T), axis=1)
    out = np.empty(m.size)
    rows = max(1, 2**20 // y.size)
    for lo in range(0, m.size, rows):
        z = (m[lo : lo + rows, None] - y[None, :]) / sigma[None, :]
        logs = np.full(z.shape, -0.0)
        near = z < LOG_NDTR_NEGLIGIBLE
        logs[near] = log_ndtr(z[near])
        out[lo : lo + rows] = np.sum(logs, axis=1)
    return out


def largest_value(y: ArrayLike, sigma: ArrayLike) -> float:
    """Estimate the largest of several true values from their measurements ``y +- sigma`` (independent, normal).

    The largest measurement is biased high: among impacts whose values are close, the one
    whose error happened to point up is the one picked (by +0.5 of its standard uncertainty
    at 5 px and 60 impacts per bat). The bias is estimated as the parametric bootstrap
    estimates it, exactly rather than by resampling: the largest of ``y_i + sigma_i z_i`` has
    the distribution function prod_i Phi((m - y_i) / sigma_i), whose mean exceeds max(y) by
    about what max(y) exceeds the largest true value. Returns max(y) minus that excess (NaN
    measurements left out; max(y) where no uncertainty is finite).
    """
    y, sigma = np.asarray(y, dtype=float), np.asarray(sigma, dtype=float)
    ok = np.isfinite(y) & np.isfinite(sigma) & (sigma > 0)
    if not ok.any():
        return float(np.nanmax(y)) if np.isfinite(y).any() else np.nan
    y, sigma = y[ok], sigma[ok]
    top = float(np.max(y))
    m = np.linspace(top - 10 * sigma.max(), float(np.max(y + 10 * sigma)), LARGEST_GRID)
    cdf = np.exp(_log_cdf(m, y, sigma))
    # E[max] = m_0 + integral of (1 - F) from m_0 (F(m_0) = 0 to double precision)
    mean = float(m[0] + np.trapezoid(1.0 - cdf, m))
    return 2 * top - mean


def _empty_sec4(ball_list: list[str], bat_list: list[str], has_truth: bool, mu_k_example: float) -> Sec4:
    """Return the Sec. IV results of these balls and bats with every fit still to be made (NaN)."""
    nb, nt = len(ball_list), len(bat_list)
    res = Sec4(
        ball_list,
        bat_list,
        has_truth,
        float(mu_k_example),
        e_x=FitGrid.empty((nb, nt)),
        e_x_pooled=FitGrid.empty((nb,)),
        tan_ratio_slope=FitGrid.empty((nb,)),
        spin_theta_slope=FitGrid.empty((nb,)),
        speed_theta_slope=FitGrid.empty((nb,)),
        per_ball={k: np.full(nb, np.nan) for k in PER_BALL},
    )
    res.per_ball["mu_k_lower_bound_impact"] = np.full(nb, -1, dtype=np.int64)
    return res


def _mu_k_bound(pb: dict, i: int, y: np.ndarray, jy: np.ndarray, sig: np.ndarray | None, impact: np.ndarray) -> None:
    """Set ball ``i``'s lower bound on mu_k (Eq. muk): the largest true tan(psi - theta), and its impact."""
    k = int(np.nanargmax(y))
    if sig is not None:
        sy = np.sqrt(np.sum(jy**2 * sig**2, axis=1))
        pb["mu_k_lower_bound"][i] = largest_value(y, sy)  # corrected for picking the largest
        pb["mu_k_lower_bound_err"][i] = float(sy[k])
    else:
        pb["mu_k_lower_bound"][i] = float(y[k])
    pb["mu_k_lower_bound_impact"][i] = int(impact[k])


def analyze_impacts(
    ds: xr.Dataset,
    mu_k_example: float,
    systematic: bool = True,
    core: bool = False,
    mu_k_bound: bool = True,
    errors: bool = True,
) -> Sec4:
    """Sec. IV analysis of a normalised and reconstructed dataset (output of ``reconstruct``).

    Uses only impacts with ``flag == 0``. The Figs. 3-4 fits read the normalised spin and
    exit speed that ``normalize`` wrote (``omega_norm``, ``v_ball_norm``) and its reference
    bat speed (attribute ``v_ref``). When the dataset holds ``truth_*`` variables
    (synthetic), each quantity also gets a truth value: the same estimator applied to the
    noise-free truth with the same weights. ``systematic=False`` skips the pixel-scale
    systematic (:func:`scale_systematic`, two more e_x fits): a replicate study asks for it only
    where its replicates draw their calibration or their properties, the combined interval's
    coverage (:func:`ballbat.studies.replicates.run_replicate`). ``core``: only e_x (per bat and
    pooled), the Eq. ratio slope and implied e_y (:func:`contact_population_error`'s refits); the
    other per-ball quantities stay NaN. ``mu_k_bound=False``: the bound on mu_k is not estimated
    (NaN; its truth is: a study's truth job, :class:`ballbat.stages.fit_ex.FitExSettings`).
    ``errors=False``: the values alone, the same numbers to the bit (every standard error and
    interval NaN: :func:`ballbat.linefit.eiv_line`'s ``errors``), for the refits whose values
    alone are read (:func:`contact_population_error`, the calibration systematics).
    """
    ds = Columns(ds)  # plain arrays: the fits read some 200 of them
    usable = ds["flag"].values == 0
    balls = ds["ball"].values.astype(str)
    bats = ds["bat"].values.astype(str)
    v_ref = float(ds.attrs["v_ref"])
    has_truth = all(f"truth_{k}" in ds for k in MEASURED)
    ball_list = sorted(set(balls))
    bat_list = sorted(set(bats))
    res = _empty_sec4(ball_list, bat_list, has_truth, mu_k_example)
    res.e_x, res.e_x_pooled = fit_e_x(ds, ball_list, bat_list, with_truth=has_truth, errors=errors)
    pb = res.per_ball
    for i, ball in enumerate(ball_list):
        in_ball = usable & (balls == ball)
        n_ball = int(in_ball.sum())
        if n_ball < MIN_FIT_IMPACTS:  # per-ball fits need the same minimum: report NaN
            for grid in (res.tan_ratio_slope, res.spin_theta_slope, res.speed_theta_slope):
                grid.fits[i] = LineFit.not_fitted(n_ball)
            continue

        r, r_x, alpha = (ds[k].values[in_ball] for k in ("r", "r_x", "alpha"))
        x, y, jx, jy = tan_ratio_design(Measured.from_dataset(ds, in_ball), r, alpha)
        sig = measured_sigma(ds, in_ball)
        bats_in_ball = ds["bat"].values[in_ball].astype(str)  # the strata of the scatter and the sandwiches
        rfit = fit_line(
            x, y, jx, jy, sig, errors_in_variables=True, strata=bats_in_ball, scatter=WITHIN_BAT_SCATTER, errors=errors
        )
        res.tan_ratio_slope.fits[i] = rfit
        exf = res.e_x_pooled.fits[i]
        a = float(np.mean(alpha))
        e_y, e_y_err = implied_e_y(ds, in_ball, res, i, (x, y, jx, jy, sig), rfit, errors)
        pb["e_y_implied"][i], pb["e_y_implied_err"][i] = e_y, e_y_err
        if core:
            continue
        if mu_k_bound:
            _mu_k_bound(pb, i, y, jy, sig, ds["impact"].values[in_ball])
        psi_g, theta_g, omega_g = gross_slip_onset(
            mu_k_example, rfit.slope, v_ref, exf.slope - 1.0, float(np.mean(r)), float(np.mean(r_x)), a
        )
        pb["gross_slip_psi"][i], pb["gross_slip_theta"][i], pb["gross_slip_omega"][i] = psi_g, theta_g, omega_g
        if has_truth:
            xt, yt, _, _ = tan_ratio_design(Measured.from_dataset(ds, in_ball, "truth_"), r, alpha)
            res.tan_ratio_slope.truth[i] = wls_slope(xt, yt, _weights(jx, jy, sig, rfit.slope, rfit, x))[0]
            pb["truth_e_y_implied"][i] = float(np.mean(ds["truth_e_y"].values[in_ball]))
            pb["truth_mu_k_lower_bound"][i] = float(np.max(yt))

        _theta_slopes(ds, res, i, in_ball, (sig, bats_in_ball), v_ref, errors)
    # impacts that carry the calibration shifts get every source by the exact rerun instead
    # (the fit_ex stage: ballbat.stages.systematics)
    res.systematic = scale_systematic(ds, res) if systematic and not has_shifts(ds) else None
    return res


def _theta_slopes(ds: Columns, res: Sec4, i: int, in_ball: np.ndarray, weights: tuple, v_ref: float, errors: bool):
    """Fit ball ``i``'s Figs. 5-6 lines (spin and exit speed against theta, normalised) into ``res``.

    ``weights``: the ball's measured uncertainties and bats (the sandwiches' strata); with the
    noise-free ``truth_*`` where ``res.has_truth``. ``errors``: :func:`analyze_impacts`'.
    """
    sig, bats_in_ball = weights
    v_bat, _, theta, _ = Measured.from_dataset(ds, in_ball)
    tv = Measured.from_dataset(ds, in_ball, "truth_") if res.has_truth else None
    for grid, which in ((res.spin_theta_slope, "omega"), (res.speed_theta_slope, "v_ball")):
        y_norm = ds[f"{which}_norm"].values[in_ball].astype(float)
        x, y, jx, jy = normalized_theta_design(v_bat, y_norm, theta, which, v_ref)
        fit = fit_line(
            x,
            y,
            jx,
            jy,
            sig,
            through_origin=False,
            robust=True,
            errors_in_variables=True,
            strata=bats_in_ball,
            errors=errors,
        )
        grid.fits[i] = fit
        if res.has_truth:
            yt_norm = normalize_to_bat_speed(tv[MEASURED.index(which)], tv[0], v_ref)
            xt, yt, _, _ = normalized_theta_design(tv[0], yt_norm, tv[2], which, v_ref)
            grid.truth[i] = wls_slope(xt, yt, _weights(jx, jy, sig, fit.slope), through_origin=False)[0]


#: Carry the contact population's estimation error into the statistical errors
#: (:func:`with_contact_error`). False: not (the studies' comparison, bench/intervals_study.py).
CONTACT_POPULATION_ERROR = True
#: The quantities that pool impacts and get the contact population's error (fit_ex.nc's names).
CONTACT_QUANTITIES = ("e_x", "e_x_pooled", "tan_ratio_slope", "e_y_implied")


def _quantity(res: Sec4, q: str) -> np.ndarray:
    """Value of a :data:`CONTACT_QUANTITIES` quantity of ``res`` (the slope for the line fits)."""
    return res.per_ball[q] if q in res.per_ball else getattr(res, q).field("slope")


def contact_population_error(ds: xr.Dataset, res: Sec4) -> dict[str, np.ndarray]:
    """Each pooled quantity's error from the contact population's estimate: half its change between +-1 sigma.

    Every ball type's contact times are a population fitted to all its impacts (the reduction's
    prior of each impact's contact, :func:`ballbat.tracks.fit_contact.contact_population`); an
    impact whose frames say little takes the population's contact time, so the error of the
    population's mean moves all of them together. The reduction solved again with the mean at
    +1 and at -1 standard error (reduce.nc's ``contact_shift_<name>``) gives the impacts at both
    sides; they are normalised, reconstructed and fitted again with the same estimators, and
    half the difference is the quantity's error from the shared estimate. It is statistical (the
    population is estimated from the same impacts and drawn afresh in every repetition).

    Parameters
    ----------
    ds : xarray.Dataset
        Reconstructed impacts carrying the shifts (:func:`ballbat.systematics.has_contact_shifts`).
    res : Sec4
        The nominal fits.

    Returns
    -------
    dict
        Per name of :data:`CONTACT_QUANTITIES`, the error (>= 0; NaN where the quantity has no value).
    """
    fits = [
        analyze_impacts(contact_shifted_impacts(ds, j), res.mu_k_example, False, core=True, errors=False)
        for j in range(len(SIDES))
    ]
    return {q: 0.5 * np.abs(_quantity(fits[0], q) - _quantity(fits[1], q)) for q in CONTACT_QUANTITIES}


def _widened(fit: LineFit, extra: float) -> LineFit:
    """``fit`` with ``extra`` added in quadrature to its standard error, its interval widened alike."""
    if not (np.isfinite(extra) and extra > 0 and np.isfinite(fit.slope_err) and fit.slope_err > 0):
        return fit
    tq = (fit.slope_ci_high - fit.slope) / fit.slope_err
    err = float(np.hypot(fit.slope_err, extra))
    return replace(fit, slope_err=err, slope_ci_low=fit.slope - tq * err, slope_ci_high=fit.slope + tq * err)


def with_contact_error(ds: xr.Dataset, res: Sec4) -> Sec4:
    """``res`` with the contact population's error (:func:`contact_population_error`) in its statistical errors.

    Added in quadrature to each quantity's standard error (and its interval widened with the
    same Student t): the shift between the two sides is the estimator's own response to the
    shared error, so its square is exactly what a covariance common to the ball type's impacts
    (the rank-one term delta delta') adds to the estimator's variance, weights unchanged.
    ``res`` unchanged where the impacts carry no shifts or :data:`CONTACT_POPULATION_ERROR` is off.
    """
    if not (CONTACT_POPULATION_ERROR and has_contact_shifts(ds)):
        return res
    err = contact_population_error(ds, res)
    for q in ("e_x", "e_x_pooled", "tan_ratio_slope"):
        grid: FitGrid = getattr(res, q)
        for idx in np.ndindex(grid.fits.shape):
            grid.fits[idx] = _widened(grid.fits[idx], float(err[q][idx]))
    extra = np.nan_to_num(err["e_y_implied"])
    res.per_ball["e_y_implied_err"] = np.hypot(res.per_ball["e_y_implied_err"], extra)
    res.contact_error = err
    return res


#: Physical bounds of a tangential COR: |u_final| <= |u_initial| (no tangential energy gain).
E_X_BOUNDS = (-1.0, 1.0)


class ImplausibleFit(ValueError):
    """A fitted e_x no ball-bat collision can have: the dataset's numbers are not to be used."""


def check_physical(res: Sec4, source: str = "fit_ex") -> None:
    """Raise :class:`ImplausibleFit` naming every fitted e_x outside :data:`E_X_BOUNDS`."""
    lo, hi = E_X_BOUNDS
    bad = []
    for name, grid in (("e_x", res.e_x), ("e_x_pooled", res.e_x_pooled)):
        e_x = grid.field("slope", -1.0)
        for idx in zip(*np.nonzero(np.isfinite(e_x) & ((e_x < lo) | (e_x > hi))), strict=True):
            where = f"ball {res.balls[idx[0]]}" + (f", bat {res.bats[idx[1]]}" if len(idx) > 1 else "")
            bad.append(f"{name} ({where}) = {e_x[idx]:.3f}")
    if bad:
        raise ImplausibleFit(
            f"{source}: fitted e_x outside the physical range [{lo:g}, {hi:g}]: {'; '.join(bad)}. No ball-bat "
            "collision gives such a value: check the units and the spin sign of the measurements (mph, deg, "
            "rpm; omega > 0 is backspin)."
        )
