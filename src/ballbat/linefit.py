"""Straight-line fits with the effective variance of each residual (lmfit).

Measurement uncertainties enter through the *effective variance* of each impact's residual:
the abscissa and the ordinate are both functions of the measured (v_bat, v_ball, theta,
omega), so the residual y - (a + s x) has variance sum_k (dy/dm_k - s dx/dm_k)^2 sigma_k^2
over the measured quantities m_k (correlations between x and y through psi included). The
weights depend on the slope, so the fit is iterated (three passes converge to far below the
standard error). Standard errors are lmfit's, scaled by the reduced chi-square (as the
paper's standard errors come from the scatter of the data); the reduced chi-square itself
tells whether the stated measurement uncertainties explain that scatter. 95 % intervals use
Student's t with n - p degrees of freedom. Where the abscissa is measured,
:func:`eiv_line` (``fit_line(errors_in_variables=True)``) removes the attenuation its noise
causes (Fuller's method-of-moments correction). Without uncertainties the fit is unweighted and
the reduced chi-square is undefined (NaN). lmfit and scipy are imported inside
:func:`fit_line` only, so that modules which merely read these names start fast.

References
----------
.. [1] J. Orear, "Least squares when both variables have uncertainties",
   Am. J. Phys. 50, 912 (1982) (effective variance).
.. [2] W. A. Fuller, *Measurement Error Models* (Wiley, 1987), Secs. 1.2 and 2.2
   (the method-of-moments correction for a measured abscissa).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

#: Fewest usable impacts for a fit of e_x per bat or pooled; fewer give NaN with n and a note.
MIN_FIT_IMPACTS = 3


def t_quantile(q: float, dof: float) -> float:
    """Student's t quantile ``q`` with ``dof`` degrees of freedom: :func:`scipy.stats.t.ppf`'s number.

    ``t.ppf`` is ``scipy.special.stdtrit`` behind argument checks and broadcasting that cost
    some 0.3 ms a call; the fits ask for one quantile each. NaN for ``dof`` <= 0, as ``t.ppf``.
    """
    from scipy.special import stdtrit

    return float(stdtrit(dof, q)) if dof > 0 and 0 < q < 1 else float("nan")


def chi2_quantile(q: float, dof: float) -> float:
    """chi^2 quantile ``q`` with ``dof`` degrees of freedom: :func:`scipy.stats.chi2.ppf`'s number (its ``_ppf``)."""
    from scipy.special import gammaincinv

    return float(2 * gammaincinv(dof / 2, q)) if dof > 0 and 0 < q < 1 else float("nan")


@dataclass(frozen=True)
class LineFit:
    """Result of a straight-line fit."""

    slope: float
    slope_err: float
    slope_ci_low: float
    slope_ci_high: float
    intercept: float  # 0 for fits through the origin
    intercept_err: float
    n: int
    redchi: float
    success: bool
    scatter: float = np.nan  # intrinsic scatter of the slope from point to point (tau; NaN: not fitted)
    scatter_ci_low: float = np.nan  # its 95 % interval (Q-profile)
    scatter_ci_high: float = np.nan

    @classmethod
    def not_fitted(cls, n: int) -> LineFit:
        """Return the result of a fit that was not made (too few impacts) or failed: NaN with ``n``."""
        return cls(np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, n, np.nan, False)


def _line(x, slope, intercept=0.0):
    return intercept + slope * x


def fit_line(
    x: ArrayLike,
    y: ArrayLike,
    jx: ArrayLike = None,
    jy: ArrayLike = None,
    sigma: ArrayLike = None,
    through_origin: bool = True,
    iterations: int = 3,
    robust: bool = False,
    errors_in_variables: bool = False,
    strata: ArrayLike | None = None,
    scatter: bool = False,
    errors: bool = True,
) -> LineFit:
    """Fit y = slope x (+ intercept) with lmfit, weighting by the effective variance.

    Parameters
    ----------
    x, y : (n,) arrays.
    jx, jy : (n, k) partial derivatives of x and y with respect to the k measured
        quantities; ``sigma`` (n, k) their standard uncertainties. All three or none.
    through_origin : fit y = slope x (Eq. omega, Eq. ratio) or a line with intercept.
    robust : standard errors from the sandwich (HC3, :func:`sandwich_cov`) instead of the
        covariance scaled by the reduced chi-square: for lines that summarise data the
        model does not describe impact by impact (Figs. 3-4: bats of different e_x, spin
        and speed not exactly linear in theta), whose scatter about the line is not the
        same everywhere.
    errors_in_variables : correct the slope for the noise of the abscissa
        (:func:`eiv_line`): the weighted least-squares slope is attenuated by the abscissa's
        measurement noise, and the moment-corrected estimator is not. Needs the
        uncertainties; without them the fit is the plain one.
    strata : with ``robust``, a label per point (its bat): the sandwich is centred within them
        (:func:`sandwich_cov`). A line pooled over bats chosen by the lab (Figs. 3-4) misses
        each bat's own line by the same amount in every repetition of the experiment; that
        misfit is not scatter, only the spread within a bat is.
    scatter : with ``errors_in_variables``, a fit through the origin whose slope varies from
        point to point (:func:`eiv_line`): a bat's e_x from impact to impact.
    errors : False: the values alone, for the refits that read only them (:func:`eiv_line`'s
        ``errors``; the lmfit fit of data without uncertainties makes its errors anyway).
    """
    weighted = sigma is not None and np.all(np.isfinite(sigma)) and np.any(np.asarray(sigma) > 0)
    if errors_in_variables and weighted:
        return eiv_line(
            x, y, jx, jy, sigma, through_origin, iterations, robust, strata, scatter and through_origin, errors
        )
    import lmfit

    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    n = x.size
    p = 1 if through_origin else 2
    if n <= p:
        return LineFit.not_fitted(n)
    model = lmfit.Model(_line, independent_vars=["x"])
    params = model.make_params(slope=1.0, intercept=0.0)
    if through_origin:
        params["intercept"].set(value=0.0, vary=False)
    # Closed-form start (ordinary least squares) keeps lmfit's iterations few.
    if through_origin:
        params["slope"].set(value=float(np.dot(x, y) / np.dot(x, x)))
    else:
        s0, c0 = np.polyfit(x, y, 1)
        params["slope"].set(value=float(s0))
        params["intercept"].set(value=float(c0))
    weights = None
    result = None
    for _ in range(iterations if weighted else 1):
        if weighted:
            s = params["slope"].value
            var = np.sum((np.asarray(jy) - s * np.asarray(jx)) ** 2 * np.asarray(sigma) ** 2, axis=1)
            if np.any(var <= 0):
                weights = None
                weighted = False
            else:
                weights = 1.0 / np.sqrt(var)
        result = model.fit(y, params, x=x, weights=weights, scale_covar=True)
        params = result.params
    if not result.success or result.params["slope"].stderr is None:
        return LineFit.not_fitted(n)
    slope = float(result.params["slope"].value)
    err = float(result.params["slope"].stderr)
    tq = t_quantile(0.975, n - p)
    icpt = 0.0 if through_origin else float(result.params["intercept"].value)
    icpt_err = 0.0 if through_origin else float(result.params["intercept"].stderr)
    if robust:
        X = x[:, None] if through_origin else np.stack([x, np.ones_like(x)], axis=1)
        w = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
        cov = sandwich_cov(X * w[:, None], (y - slope * x - icpt) * w, strata)
        err = float(np.sqrt(cov[0, 0]))
        icpt_err = 0.0 if through_origin else float(np.sqrt(cov[1, 1]))
    return LineFit(
        slope=slope,
        slope_err=err,
        slope_ci_low=slope - tq * err,
        slope_ci_high=slope + tq * err,
        intercept=icpt,
        intercept_err=icpt_err,
        n=n,
        redchi=float(result.redchi) if weighted else np.nan,
        success=True,
    )


def eiv_line(
    x: ArrayLike,
    y: ArrayLike,
    jx: ArrayLike,
    jy: ArrayLike,
    sigma: ArrayLike,
    through_origin: bool = True,
    iterations: int = 3,
    robust: bool = False,
    strata: ArrayLike | None = None,
    scatter: bool = False,
    errors: bool = True,
) -> LineFit:
    """Straight line through data whose abscissa is measured: the moment-corrected weighted fit.

    The weighted least-squares slope of y on a noisy x is attenuated: the noise adds
    sum W var(x_i) to the spread of x (and sum W cov(x_i, y_i) to its covariance with y).
    With the measurement uncertainties known, both are subtracted (the method-of-moments
    estimator of Fuller, *Measurement Error Models*, 1987, Secs. 1.2 and 2.2):

        beta = (X'WX - N)^-1 (X'Wy - c),

    X the design (x, and a column of ones with an intercept), W the effective-variance
    weights (iterated with the slope as in :func:`fit_line`), N = diag(sum W var x_i, 0) and
    c = (sum W cov(x_i, y_i), 0), with var x_i = sum_k jx_ik^2 sigma_ik^2 and cov(x_i, y_i)
    = sum_k jx_ik jy_ik sigma_ik^2 from the Jacobians. It estimates the weighted
    least-squares line of the noise-free values, whether or not the data scatter about a
    line by more than their noise (the Figs. 3-4 lines do; orthogonal distance regression
    assumes they do not, and would then over-correct). Without noise in x it is the weighted
    least-squares fit.

    Standard errors: the covariance of the weighted fit with the residuals at beta, carried
    through (X'WX - N)^-1 (the delta method; the term of order sigma_x^4 is left out): the
    reduced-chi-square-scaled covariance, or with ``robust`` the HC3 sandwich
    (:func:`sandwich_cov`, centred within ``strata`` when given). 95 % intervals use
    Student's t with n - p degrees of freedom.

    With ``scatter`` (and :data:`SCATTER_TERM`; a line through the origin), the slope of each
    point may differ from the line's by an intrinsic scatter tau (a bat's e_x from impact to
    impact): its part of the residual is tau x_i, so each point's variance gains tau^2 g_i
    (:func:`scatter_gain`) and the weights are 1 / (effective variance + tau^2 g_i), with tau^2
    of Paule and Mandel (:func:`paule_mandel`: the weighted residuals' chi-square equals its
    n - p degrees of freedom; 0 where it is below them), iterated with the slope. tau and its
    95 % Q-profile interval are in the fit's ``scatter*`` fields. Where tau is 0 the fit is the
    one without the term. With ``strata`` (a line pooled over bats, each with a slope of its
    own that every repetition keeps), tau is the scatter *within* them: the residuals about each
    stratum's own moment-corrected slope, with n minus the number of strata degrees of freedom
    (:func:`_scatter_residuals`); the bats' differences are the design's, not scatter.
    A corrected spread of x that is not positive (noise as large as the spread of the
    abscissa) gives a fit not made (NaN).

    ``errors=False``: the values alone (slope, intercept, tau), the same numbers to the bit; the
    errors, intervals, reduced chi-square and tau's interval NaN, and ``success`` whether the
    slope is finite. For the refits whose values alone are read (the calibration systematics
    and the contact population's error: :func:`ballbat.fitting.analyze_impacts`).
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    jx, jy, sig2 = np.asarray(jx, dtype=float), np.asarray(jy, dtype=float), np.asarray(sigma, dtype=float) ** 2
    n = x.size
    p = 1 if through_origin else 2
    if n <= p:
        return LineFit.not_fitted(n)
    X = x[:, None] if through_origin else np.stack([x, np.ones_like(x)], axis=1)
    var_x = np.sum(jx**2 * sig2, axis=1)
    cov_xy = np.sum(jx * jy * sig2, axis=1)
    beta = np.linalg.lstsq(X, y, rcond=None)[0]
    scatter = scatter and SCATTER_TERM and through_origin
    g = scatter_gain(x, var_x)
    fit = _eiv_passes(X, y, (jx, jy, sig2, var_x, cov_xy, g), beta, iterations, scatter, strata)
    if fit is None:
        return LineFit.not_fitted(n)
    beta, tau2, scatter, W, xwx, A, var0 = fit
    if not errors:
        return LineFit(
            slope=float(beta[0]),
            slope_err=np.nan,
            slope_ci_low=np.nan,
            slope_ci_high=np.nan,
            intercept=0.0 if through_origin else float(beta[1]),
            intercept_err=np.nan,
            n=n,
            redchi=np.nan,
            success=bool(np.isfinite(beta[0])),
            scatter=float(np.sqrt(tau2)) if scatter else np.nan,
        )
    r = y - X @ beta
    w = np.sqrt(W)
    redchi = float(np.sum(W * r**2) / (n - p))
    if robust:
        inner = xwx @ sandwich_cov(X * w[:, None], r * w, strata) @ xwx
    else:
        inner = knapp_hartung_factor(redchi, scatter and strata is None) * xwx
    Ainv = np.linalg.inv(A)
    cov = Ainv @ inner @ Ainv
    slope, err = float(beta[0]), float(np.sqrt(cov[0, 0]))
    tq = t_quantile(0.975, n - p)
    tau = (np.nan, np.nan, np.nan)
    if scatter:  # tau and its interval from the final residuals (within strata where given)
        r_s, dof_s = _scatter_residuals(r, x, y, var_x, cov_xy, 1.0 / W, strata, n - p)
        tau = (np.sqrt(tau2), *scatter_interval(r_s, var0, g, dof_s))
    return LineFit(
        slope=slope,
        slope_err=err,
        slope_ci_low=slope - tq * err,
        slope_ci_high=slope + tq * err,
        intercept=0.0 if through_origin else float(beta[1]),
        intercept_err=0.0 if through_origin else float(np.sqrt(cov[1, 1])),
        n=n,
        redchi=redchi,
        success=bool(np.isfinite(slope) and np.isfinite(err)),
        scatter=float(tau[0]),
        scatter_ci_low=float(tau[1]),
        scatter_ci_high=float(tau[2]),
    )


def _eiv_passes(X, y, noise: tuple, beta, iterations: int, scatter: bool, strata) -> tuple | None:
    """:func:`eiv_line`'s passes of the weights, tau^2 and the slope, from the start ``beta``.

    ``noise``: ``(jx, jy, sig2, var_x, cov_xy, g)``. Returns ``(beta, tau2, scatter, W, xwx, A,
    var0)`` at the last pass (``scatter`` False where tau^2 could not be estimated), or None for
    a fit not made (an effective variance or a corrected spread of x that is not positive).

    Each pass: the effective variances var0 at the slope so far; with ``scatter``, from the
    last of the ``iterations`` on, Paule and Mandel's tau^2 from the residuals (within
    ``strata``: :func:`_scatter_residuals`; not finite where the points at x ~ 0 alone exceed
    the residuals' degrees of freedom, or none is left: the fit goes on without the term);
    the weights 1 / (var0 + tau^2 g) and the moment-corrected slope. A pass whose slope and
    tau^2 are those it started from, to the bit, among the passes of one kind (after the
    first, or after the first with tau^2) is a fixed point: every later pass would repeat it
    exactly, so the loop ends there with the same numbers (:data:`STOP_AT_FIXED_POINT`).
    The passes run compiled, as one call (:func:`ballbat.linefit_kernels.passes`).
    """
    from . import linefit_kernels as kern

    jx, jy, sig2, var_x, cov_xy, g = (np.ascontiguousarray(a, dtype=float) for a in noise)
    idx, nstrata = np.zeros(y.size, dtype=np.int64), 1
    if strata is not None:
        _, inv = np.unique(np.asarray(strata), return_inverse=True)
        idx, nstrata = inv.reshape(-1).astype(np.int64), int(inv.max()) + 1
    status, beta, tau2, scatter, W, xwx, A, var0, _ = kern.passes(
        np.ascontiguousarray(X, dtype=float),
        np.ascontiguousarray(y, dtype=float),
        jx,
        jy,
        sig2,
        var_x,
        cov_xy,
        g,
        np.asarray(beta, dtype=float),
        iterations,
        SCATTER_PASSES,
        bool(scatter),
        idx,
        nstrata,
        STOP_AT_FIXED_POINT,
    )
    if status != kern.FITTED:
        return None
    return beta, tau2, scatter, W, xwx, A, var0


def _scatter_residuals(
    r: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    var_x: np.ndarray,
    cov_xy: np.ndarray,
    v: np.ndarray,
    strata: ArrayLike | None,
    dof: int,
) -> tuple[np.ndarray, int]:
    """Return the residuals and degrees of freedom that the intrinsic scatter is estimated from.

    Without strata (or with one): the line's own residuals ``r`` and ``dof``. With strata:
    each point's residual about its stratum's own slope through the origin, moment-corrected
    as the line is (sum W (x y - cov) / sum W (x^2 - var x), weights W = 1 / ``v``), and one
    degree of freedom per stratum so fitted. A stratum whose corrected spread of x is not
    positive keeps the line's slope and costs no degree of freedom.
    """
    if strata is None:
        return r, dof
    labels = np.asarray(strata)
    _, idx = np.unique(labels, return_inverse=True)
    if idx.max() == 0:
        return r, dof
    w = 1.0 / v
    num = np.bincount(idx, w * (x * y - cov_xy))
    den = np.bincount(idx, w * (x * x - var_x))
    own = den > 0
    slope = np.where(own, num / np.where(own, den, 1.0), np.nan)
    out = np.where(own[idx], y - slope[idx] * x, r)
    return out, int(x.size - own.sum())


#: Fit the intrinsic-scatter term where a fit asks for it (:func:`eiv_line`'s ``scatter``).
SCATTER_TERM = True

#: End :func:`eiv_line`'s passes at their fixed point (a pass that returns the slope and tau^2 it started
#: from, to the bit: the rest would repeat it). False: every pass made (tests compare the two).
STOP_AT_FIXED_POINT = True

#: Passes of the slope and tau^2 after the fit without the term (both settle in three to four).
SCATTER_PASSES = 5


#: The modified Knapp-Hartung floor of a fit with the intrinsic-scatter term (:func:`knapp_hartung_factor`).
#: Measured and not shipped (docs/studies.md, "Intervals everywhere"): False, the reduced chi-square as it
#: comes; True only for bench/intervals_study.py's comparison.
KNAPP_HARTUNG_FLOOR = False


def knapp_hartung_factor(redchi: float, scatter: bool) -> float:
    """Return the factor of the covariance of a fit: the reduced chi-square, floored at 1 where asked.

    With the intrinsic-scatter term the scaled covariance is Knapp and Hartung's (Stat. Med. 22,
    2693 (2003)): the weights 1 / (v_i + tau^2 g_i) and the weighted residuals' chi-square over
    n - p, with Student's t on n - p degrees of freedom. Paule and Mandel's tau^2 makes that
    ratio exactly 1 where tau > 0 and below 1 where tau is 0. The modified interval (Knapp and
    Hartung 2003; Roever, Knapp and Friede, BMC Med. Res. Methodol. 15, 99 (2015)) floors it at 1
    (:data:`KNAPP_HARTUNG_FLOOR`, with ``scatter``). Measured on e_x per bat it did not mend the
    short intervals of small samples with scatter (88.3 -> 90.0 %) and over-covered without
    scatter (97-99 %), so it is off; e_x per bat's error is the HC3 sandwich instead
    (:data:`ballbat.fitting.PER_BAT_SANDWICH`).
    """
    if scatter and KNAPP_HARTUNG_FLOOR:
        return max(1.0, redchi)
    return redchi


def scatter_gain(x: ArrayLike, var_x: ArrayLike) -> np.ndarray:
    """Each point's factor g_i of the intrinsic-scatter variance tau^2 g_i: its true x^2, x^2 - var x (not below 0)."""
    x = np.asarray(x, dtype=float)
    return np.clip(x * x - np.asarray(var_x, dtype=float), 0.0, None)


def _q_root(r2: np.ndarray, v0: np.ndarray, g: np.ndarray, target: float) -> float:
    """tau^2 >= 0 where sum r^2 / (v0 + tau^2 g) equals ``target`` (0 where it is below at tau^2 = 0).

    inf where no tau brings it down to the target (the points with g = 0 alone exceed it).
    Newton's method on the reciprocal, compiled (:func:`ballbat.linefit_kernels.q_root`).
    """
    from .linefit_kernels import q_root

    return float(q_root(*(np.ascontiguousarray(a, dtype=float) for a in (r2, v0, g)), float(target)))


def paule_mandel(r: ArrayLike, v0: ArrayLike, g: ArrayLike, dof: int) -> float:
    """Paule-Mandel tau^2: the chi-square of the residuals ``r`` with variances v0 + tau^2 g equals ``dof``.

    Parameters
    ----------
    r : ndarray
        Residuals of the fit.
    v0 : ndarray
        Their measurement variances (positive).
    g : ndarray
        Each residual's factor of the intrinsic variance (:func:`scatter_gain`).
    dof : int
        Degrees of freedom of the residuals (at least 1).

    Returns
    -------
    float
        tau^2 (0 where the measurement errors explain the scatter).
    """
    if dof < 1:
        raise ValueError(f"paule_mandel: needs at least 1 degree of freedom, not {dof}")
    r, v0, g = (np.asarray(a, dtype=float) for a in (r, v0, g))
    return _q_root(r * r, v0, g, float(dof))


def scatter_interval(r: ArrayLike, v0: ArrayLike, g: ArrayLike, dof: int) -> tuple[float, float]:
    """95 % Q-profile interval of tau (Viechtbauer 2007): where the residuals' chi-square lies within its 2.5-97.5 %."""
    r2 = np.asarray(r, dtype=float) ** 2
    v0, g = np.asarray(v0, dtype=float), np.asarray(g, dtype=float)
    lo = _q_root(r2, v0, g, chi2_quantile(0.975, dof))
    hi = _q_root(r2, v0, g, chi2_quantile(0.025, dof))
    return float(np.sqrt(lo)), float(np.sqrt(hi))


def strata_blocks(n: int, strata: ArrayLike | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Stratum index of each row, and per stratum its size n_b, the factor f_b and the centering switch c_b.

    Without strata every row is one uncentred block (f = 1, c = 0): the plain sandwich. With
    strata, each stratum's scores are centred on their mean (c = 1) and scaled by
    f_b = n_b/(n_b - 1). Strata of one row cannot be centred; they are pooled into one
    stratum, which stays uncentred (f = 1, c = 0) if it holds a single row.
    """
    if strata is None:
        return np.zeros(n, dtype=np.int64), np.array([float(n)]), np.ones(1), np.zeros(1)
    labels = np.asarray(strata)
    if labels.shape != (n,):
        raise ValueError(f"sandwich: strata must have one label per row ({n}); got shape {labels.shape}")
    _, idx, counts = np.unique(labels, return_inverse=True, return_counts=True)
    single = counts[idx] == 1
    idx = np.where(single, counts.size, idx)  # pool the single-row strata
    _, idx = np.unique(idx, return_inverse=True)
    nb = np.bincount(idx).astype(float)
    centred = nb > 1
    f = np.where(centred, nb / np.maximum(nb - 1.0, 1.0), 1.0)
    return idx, nb, f, centred.astype(float)


def _hc3_parts(J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(J'J)^-1 and the leverages h_i = J_i (J'J)^-1 J_i'."""
    A = np.linalg.inv(J.T @ J)
    h = np.einsum("ij,jk,ik->i", J, A, J)
    return A, np.minimum(h, 1.0 - 1e-12)


def sandwich_cov(J: ArrayLike, r: ArrayLike, strata: ArrayLike | None = None) -> np.ndarray:
    """Heteroscedasticity-consistent (HC3) covariance of least-squares parameters.

    ``J`` (n, p) is the Jacobian of the weighted model (for a line, the weighted design
    matrix) and ``r`` (n,) the weighted residuals at the fit. The covariance is
    (J'J)^-1 M (J'J)^-1 with the scores u_i = J_i r_i / (1 - h_i) and the leverages h_i
    (MacKinnon and White 1985): it holds whether or not the scatter about the model is the
    same for every point, and whether or not the stated uncertainties explain it.

    Without ``strata``, M = sum_i u_i u_i'. With ``strata`` (one label per row: the fixed
    groups of a stratified design, such as the bats of an experiment whose number of impacts
    per bat is chosen), M = sum_b n_b/(n_b - 1) sum_{i in b} (u_i - u_b)(u_i - u_b)' with u_b
    the stratum's mean score: a misfit common to a stratum is the same in every repetition
    of the design and is not counted as scatter (the stratified variance of survey sampling,
    e.g. Cochran, *Sampling Techniques*, 3rd ed., Sec. 5.3). Strata of one row are pooled.

    Returns
    -------
    ndarray
        (p, p).
    """
    J = np.asarray(J, dtype=float)
    r = np.asarray(r, dtype=float)
    A, h = _hc3_parts(J)
    if strata is None:
        u = r / (1.0 - h)
        return A @ (J.T @ (u[:, None] ** 2 * J)) @ A
    u = J * (r / (1.0 - h))[:, None]
    idx, nb, f, c = strata_blocks(J.shape[0], strata)
    mean = np.zeros((f.size, u.shape[1]))
    np.add.at(mean, idx, u)
    u = u - (c / nb)[idx, None] * mean[idx]
    B = (u * f[idx, None]).T @ u
    return A @ B @ A


def sandwich_dof(J: ArrayLike, strata: ArrayLike | None = None, column: int = 0) -> float:
    """Bell-McCaffrey degrees of freedom of one parameter's :func:`sandwich_cov` variance.

    The sandwich variance of parameter ``column`` is a quadratic form r'Wr in the residuals.
    If the errors were independent with equal variance, it would be distributed as a
    multiple of chi^2 with nu = (tr W)^2 / tr(W^2) degrees of freedom (Satterthwaite); the
    interval uses Student's t with nu (Bell and McCaffrey, Survey Methodology 28, 169 (2002);
    Imbens and Kolesar, Rev. Econ. Stat. 98, 701 (2016)). nu depends on the design only, not
    on the residuals, and is smaller than n - p when a few points carry the fit: the variance
    estimate then rests on few of them. Computed in O(n p^2) from the low-rank structure of W.

    Parameters
    ----------
    J : (n, p) Jacobian of the weighted model at the fit.
    strata : labels as for :func:`sandwich_cov`, or None.
    column : the parameter.

    Returns
    -------
    float
    """
    J = np.asarray(J, dtype=float)
    n = J.shape[0]
    A, h = _hc3_parts(J)
    a = (J @ A[:, column]) / (1.0 - h)  # the diagonal of D: the parameter's score weights
    idx, nb, f, c = strata_blocks(n, strata)
    K = J @ A  # the projection onto the model is P = K J'

    def apply_b(X: np.ndarray) -> np.ndarray:
        """B X with B = D C D: per stratum f_b (diag(a^2) - c_b a a'/n_b)."""
        s = np.zeros((f.size, X.shape[1]))
        np.add.at(s, idx, a[:, None] * X)
        return f[idx, None] * (a[:, None] ** 2 * X - (c / nb)[idx, None] * a[:, None] * s[idx])

    a2 = np.bincount(idx, weights=a**2, minlength=f.size)
    a4 = np.bincount(idx, weights=a**4, minlength=f.size)
    tr_b = float(np.sum(f * (1.0 - c / nb) * a2))
    tr_bb = float(np.sum(f**2 * (a4 - 2.0 * c * a4 / nb + c * a2**2 / nb**2)))
    BK = apply_b(K)
    Q = J.T @ BK  # tr(B P) = tr(Q)
    tr_bbp = float(np.trace(J.T @ apply_b(BK)))
    tr_w = tr_b - float(np.trace(Q))
    tr_ww = tr_bb - 2.0 * tr_bbp + float(np.trace(Q @ Q))
    return tr_w**2 / tr_ww


def wls_slope(
    x: ArrayLike, y: ArrayLike, weights: ArrayLike = None, through_origin: bool = True
) -> tuple[float, float]:
    """Weighted least-squares (slope, intercept) in closed form (used for truth values)."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    w = np.ones_like(x) if weights is None else np.asarray(weights, dtype=float) ** 2
    if through_origin:
        return float(np.sum(w * x * y) / np.sum(w * x * x)), 0.0
    xm = np.sum(w * x) / np.sum(w)
    ym = np.sum(w * y) / np.sum(w)
    s = np.sum(w * (x - xm) * (y - ym)) / np.sum(w * (x - xm) ** 2)
    return float(s), float(ym - s * xm)


def effective_sigma(jx: ArrayLike, jy: ArrayLike, sigma: ArrayLike, slope: ArrayLike) -> np.ndarray | None:
    """Return the standard deviation of y - slope x from the measurement uncertainties (effective variance)."""
    if sigma is None:
        return None
    return np.sqrt(np.sum((jy - slope * jx) ** 2 * sigma**2, axis=1))
