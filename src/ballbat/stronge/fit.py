"""Fit of Stronge's eta^2 to the Eq. (vtf) data of one ball (Sec. V.A, Fig. 9 of Kensrud et al.).

The data are ``y = (v_ball,t + r omega)/v_bat,n`` against ``x = tan(psi)/(1 + r_x)``
(Eq. vtf); the model is ``y = (1 + e_x(psi; eta2, e_y, mu, r_x, r_y)) x`` with e_x from
:func:`ballbat.stronge.model.stronge_ex` in the bat's frame, each impact with its own recoil
factors. The paper fitted eta^2 = 4.75 (baseball) and 6.30 (softball) with e_y = mu = 0.5.

Uncertainties (documented in docs/stronge.md, "The eta^2 fit"):

* ``robust=False`` (default): the standard error is lmfit's, from the covariance of the
  least-squares fit. With ``scale_covar=True`` (default) the covariance is scaled by the
  reduced chi-square, as the paper's error bars are "estimates based on the fluctuation of
  the data about a smooth line"; with ``sigma=None`` this is the only meaningful choice.
* ``robust=True`` (the workflow's fit, :func:`ballbat.stronge.analysis.fit_ball`): the
  standard error is the HC3 sandwich, centred within ``strata`` (the bats:
  :func:`ballbat.linefit.sandwich_cov`), with Bell-McCaffrey degrees of freedom
  (:func:`ballbat.linefit.sandwich_dof`). One eta^2 does not describe bats of different e_x
  exactly, so the scatter about the curve is neither the same for every impact nor noise
  alone: the part common to a bat is the same whenever its impacts are repeated.
* The profile-likelihood interval is where chi^2(eta2) (minimised over the free nuisance
  parameters, if any) exceeds its minimum by Delta. Not robust: ``chi2.ppf(level, 1)``
  (3.84 for 95 %), multiplied by the reduced chi-square of the best fit when
  ``scale_covar=True``, the same scaling as the covariance. Robust: t_nu^2 (quantile of
  Student's t with the Bell-McCaffrey nu) times the ratio of the robust to the unscaled
  variance. Either way the interval is +-(quantile) standard errors for a model linear in
  eta2, and follows the curvature of chi^2 otherwise.

The fit is Levenberg-Marquardt (MINPACK): with e_y and mu fixed it is lmfit's ``leastsq``
computed without lmfit's Parameters (:func:`_lm_eta2_alone`, the same numbers), otherwise
lmfit's. lmfit and scipy are imported inside :func:`fit_eta2` only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .model import ImpactGeometry

__all__ = ["Eta2Fit", "Eta2FitError", "fit_eta2"]


class Eta2FitError(RuntimeError):
    """The eta^2 fit failed; the message names the inputs."""


@dataclass(frozen=True)
class Eta2Fit:
    """Result of :func:`fit_eta2`. Errors of fixed parameters are NaN."""

    eta2: float
    eta2_err: float
    eta2_ci_low: float  # profile-likelihood interval (NaN if it does not close within bounds)
    eta2_ci_high: float
    e_y: float
    e_y_err: float
    mu: float
    mu_err: float
    chisqr: float
    redchi: float
    n: int
    nfree: int
    dof: float  # degrees of freedom of eta2_err (nfree, or Bell-McCaffrey's when robust)
    robust: bool
    level: float
    delta_chi2: float  # the chi^2 rise that defines the interval (after scaling)
    scale_covar: bool
    success: bool
    message: str


class _Described:
    """The inputs of a fit in words (:func:`_describe`), written only when a message needs them."""

    def __init__(self, *args) -> None:
        self.args = args

    def __str__(self) -> str:
        return _describe(*self.args)

    def __format__(self, spec: str) -> str:
        return format(str(self), spec)


def _describe(psi, e_y, mu, vary_e_y, vary_mu) -> str:
    psi = np.asarray(psi, dtype=float)
    with np.errstate(invalid="ignore"):
        rng = f"{np.nanmin(np.degrees(psi)):.3g}..{np.nanmax(np.degrees(psi)):.3g} deg" if psi.size else "empty"
    return (
        f"n={psi.size} impacts, psi {rng}, e_y={e_y:g} ({'free' if vary_e_y else 'fixed'}),"
        f" mu={mu:g} ({'free' if vary_mu else 'fixed'})"
    )


def _jacobian(residual, at: dict[str, float], names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Central-difference Jacobian (n, len(names)) of ``residual(eta2, e_y, mu)`` at ``at``, and the residual there.

    One call of ``residual`` with the parameters as columns (m, 1) evaluates ``at`` and the
    two steps of every parameter at once: the model is elementwise, so each row is the
    residual a call at that point alone gives (to round-off: the Newton iterations of
    :func:`ballbat.stronge.model.stronge_ex` stop when the whole batch has converged).
    """
    points = [dict(at)]
    steps = []
    for k in names:
        h = 1e-6 * max(abs(at[k]), 1e-3)
        up, down = dict(at), dict(at)
        up[k] += h
        down[k] -= h
        points += [up, down]
        steps.append(h)
    col = {q: np.array([pt[q] for pt in points])[:, None] for q in ("eta2", "e_y", "mu")}
    rows = residual(col["eta2"], col["e_y"], col["mu"])
    cols = [(rows[1 + 2 * i] - rows[2 + 2 * i]) / (2 * h) for i, h in enumerate(steps)]
    return np.stack(cols, axis=1), rows[0]


#: lmfit's ``lineshapes.tiny`` (1e-15): a start closer to 0 than this is 0 (lmfit 1.3.4; a test
#: compares them). Its own constant, not lmfit's import (0.14 s at each job's first fit).
LMFIT_TINY = 1e-15

#: lmfit's settings of ``scipy.optimize.leastsq`` (MINPACK's lmdif) in ``Minimizer.leastsq`` (lmfit 1.3).
LMFIT_LEASTSQ = dict(ftol=1.5e-8, xtol=1.5e-8, gtol=0.0, epsfcn=1.0e-10, factor=100)
#: lmfit's ceiling of function evaluations for one varied parameter, 2000 (nvarys + 1).
LMFIT_MAX_NFEV = 4000
#: The bounds lmfit's Parameters hold e_y and mu in (a fixed value is clipped into them as well).
E_Y_BOUNDS, MU_BOUNDS = (0.05, 1.0), (1e-3, 10.0)
#: lmfit's messages for MINPACK's other outcomes (``ier``; 1-3: "Fit succeeded.").
LMFIT_MESSAGES = {
    0: "Invalid Input Parameters. I.e. more variables than data points given, tolerance < 0.0, or no data provided.",
    4: "One or more variable did not affect the fit.",
    5: f"Too many function calls (max set to {2 * LMFIT_MAX_NFEV:d})! Use: minimize(func, params, ..., max_nfev=NNN)"
    " to increase this maximum.",
}


@dataclass
class _LeastSquares:
    """What :func:`fit_eta2` keeps of a least-squares fit: values, lmfit's standard errors (NaN: fixed), chi^2."""

    values: dict[str, float]
    stderr: dict[str, float]
    vary: tuple[str, ...]
    chisqr: float
    nfree: int
    success: bool
    message: str
    params: object = None  # lmfit's Parameters at the fit (the profile with free nuisance parameters)


def _least_squares(residual, start: tuple, bounds: tuple, vary: tuple, scale_covar: bool, what: str) -> _LeastSquares:
    """Return the Levenberg-Marquardt fit of ``residual(eta2, e_y, mu)`` from ``start`` (eta2, e_y, mu).

    eta^2 is held in ``bounds``; e_y (0.05-1) and mu (0.001-10) vary where ``vary`` says. With
    e_y and mu fixed, lmfit's own computation without its Parameters (:func:`_lm_eta2_alone`, the
    same numbers); otherwise lmfit.
    """
    if not any(vary):
        try:
            return _lm_eta2_alone(residual, start, bounds, scale_covar)
        except ValueError as exc:
            raise Eta2FitError(f"fit_eta2: the least-squares fit raised {exc!r} ({what})") from exc
    import lmfit

    params = lmfit.Parameters()
    params.add("eta2", value=start[0], min=bounds[0], max=bounds[1])
    params.add("e_y", value=start[1], min=E_Y_BOUNDS[0], max=E_Y_BOUNDS[1], vary=vary[0])
    params.add("mu", value=start[2], min=MU_BOUNDS[0], max=MU_BOUNDS[1], vary=vary[1])

    def fcn(p):
        return residual(p["eta2"].value, p["e_y"].value, p["mu"].value)

    try:
        res = lmfit.minimize(fcn, params, method="leastsq", scale_covar=scale_covar)
    except (ValueError, RuntimeError) as exc:  # pragma: no cover - lmfit internals
        raise Eta2FitError(f"fit_eta2: lmfit raised {exc!r} ({what})") from exc
    names = ("eta2", "e_y", "mu")
    return _LeastSquares(
        values={k: res.params[k].value for k in names},
        stderr=_lmfit_errors(res.params),
        vary=tuple(k for k in names if res.params[k].vary),
        chisqr=float(res.chisqr),
        nfree=int(res.nfree),
        success=bool(res.success),
        message=str(res.message),
        params=res.params,
    )


def _lm_eta2_alone(residual, start: tuple, bounds: tuple, scale_covar: bool) -> _LeastSquares:
    """Fit eta^2 alone (e_y and mu fixed) as lmfit's ``leastsq`` does, without its Parameters.

    lmfit (1.3) varies a parameter bounded on both sides through the internal v with
    ``eta2 = lo + (sin v + 1)(hi - lo)/2`` (clipped into the bounds), calls
    ``scipy.optimize.leastsq`` with :data:`LMFIT_LEASTSQ`, evaluates the residual once more at
    the result and scales MINPACK's covariance by ``(cos v (hi - lo)/2)^2`` and, with
    ``scale_covar``, the reduced chi^2. These are the same operations on the same numbers, so
    value, chi^2, standard error and message are lmfit's to the bit (a test compares them);
    what is left out is the bookkeeping of its Parameters, about 3 ms a fit.
    """
    from scipy.optimize import leastsq

    lo, hi = bounds
    e_y, mu = (min(max(v, b[0]), b[1]) for v, b in zip(start[1:], (E_Y_BOUNDS, MU_BOUNDS), strict=True))
    v0 = float(np.arcsin(2 * (min(max(start[0], lo), hi) - lo) / (hi - lo) - 1))
    nfev = [0]

    def external(v) -> float:
        return min(max(float(lo + (np.sin(v) + 1) * (hi - lo) / 2.0), lo), hi)

    def fcn(fvars):
        nfev[0] += 1
        if nfev[0] > LMFIT_MAX_NFEV:
            raise ValueError(f"fit aborted: too many function evaluations {LMFIT_MAX_NFEV}")
        r = np.asarray(residual(external(fvars.reshape(1)[0]), e_y, mu), dtype=np.float64).ravel()
        if not np.isfinite(np.sum(r)):
            raise ValueError("NaN values detected in the output of the objective function")
        return r

    best, cov, _info, _msg, ier = leastsq(
        fcn,
        [0.0 if abs(v0) < LMFIT_TINY else v0],
        full_output=1,
        col_deriv=0,
        maxfev=2 * LMFIT_MAX_NFEV,
        **LMFIT_LEASTSQ,
    )
    r = fcn(best)
    chisqr, nfree = float((r**2).sum()), r.size - 1
    message = "Fit succeeded." if ier in {1, 2, 3} else LMFIT_MESSAGES.get(ier, "Tolerance seems to be too small.")
    err = np.nan
    if cov is None:
        message += " Could not estimate error-bars."
    else:
        grad = np.cos(best[0]) * (hi - lo) / 2.0
        covar = cov * np.dot(np.atleast_2d([grad]).T, np.atleast_2d([grad]))
        if scale_covar:
            covar *= chisqr / max(1, nfree)
        err = float(np.sqrt(covar[0, 0]))
    return _LeastSquares(
        values={"eta2": external(best[0]), "e_y": e_y, "mu": mu},
        stderr={"eta2": err, "e_y": np.nan, "mu": np.nan},
        vary=("eta2",),
        chisqr=max(chisqr, 1e-250 * r.size),
        nfree=nfree,
        success=ier in (1, 2, 3, 4),
        message=message,
    )


def fit_eta2(
    psi: ArrayLike,
    x: ArrayLike,
    y: ArrayLike,
    r_x: ArrayLike,
    r_y: ArrayLike,
    sigma: ArrayLike | None = None,
    e_y: float = 0.5,
    mu: float = 0.5,
    alpha: ArrayLike = 0.4,
    vary_e_y: bool = False,
    vary_mu: bool = False,
    eta2_bounds: tuple[float, float] = (1.0, 30.0),
    scale_covar: bool = True,
    level: float = 0.95,
    robust: bool = False,
    strata: ArrayLike | None = None,
    interval: bool = True,
    errors: bool = True,
    start: float | None = None,
) -> Eta2Fit:
    """Fit eta^2 (and optionally e_y, mu) of Stronge's model to Eq. (vtf) data.

    Parameters
    ----------
    psi : incidence angle of each impact, rad.
    x : ``tan(psi)/(1 + r_x)`` of each impact (the bracket of Eq. vtf).
    y : ``(v_ball,t + r omega)/v_bat,n`` of each impact (the LHS of Eq. vtf).
    r_x, r_y : recoil factors of each impact's bat (Eqs. rx and ry); broadcast to psi.
    sigma : uncertainty of each y (None: unweighted).
    e_y, mu : values (fixed) or starting values (when ``vary_e_y``/``vary_mu``).
    alpha : I_ball/(m r^2).
    eta2_bounds : search range of eta^2. The scan that picks the starting value and the
        profile interval are confined to it.
    scale_covar : scale the covariance (and the profile threshold) by the reduced chi^2
        (not robust).
    level : confidence level of the profile-likelihood interval.
    robust : standard errors from the sandwich centred within ``strata``, with
        Bell-McCaffrey degrees of freedom (module docstring).
    strata : a label per impact (its bat) for ``robust``; None: one uncentred stratum.
    interval : compute the profile-likelihood interval (False: NaN, for fits whose value
        alone is wanted, such as a replicate study's noise-free truth).
    errors : compute the standard errors and their degrees of freedom (False: NaN; the value
        alone, e.g. a replicate study's noise-free truth; needs ``interval=False``).
    start : the least-squares fit's starting eta^2 in place of the scan's (None: the scan). For a
        fit whose minimum lies next to a known one: the calibration systematics' refits start at
        the nominal fit (:func:`ballbat.stages.stronge.stronge_shifts`), which also keeps them in
        its basin where e_x(eta^2) is not monotonic. A start outside ``eta2_bounds`` or not finite
        is the scan's.

    Returns
    -------
    Eta2Fit

    Raises
    ------
    ValueError
        Inputs of different lengths, non-finite values or too few impacts.
    Eta2FitError
        lmfit reports failure or returns a non-finite eta^2.

    Notes
    -----
    Model: Eq. (vtf) of Kensrud et al. (2017) with e_x from Stronge's contact model
    (Sec. V.A), ``y = (1 + e_x) x``. Because e_x(eta2) is not monotonic over all eta2 (for
    eta2 < 3.5 the tangential vibration can go through more than half a period), the
    starting value is the best of a logarithmic scan of ``eta2_bounds``; the local
    least-squares fit (lmfit, Levenberg-Marquardt) starts there.
    """
    psi = np.asarray(psi, dtype=float).ravel()
    what = _Described(psi, e_y, mu, vary_e_y, vary_mu)
    x, y, r_x, r_y, alpha, sig = _checked_inputs(psi, x, y, r_x, r_y, alpha, sigma, vary_e_y, vary_mu, what)

    geometry = ImpactGeometry(psi, r_x, r_y, alpha)
    residual = _Residual(geometry, x, y, sig)
    bounds = (float(eta2_bounds[0]), float(eta2_bounds[1]))
    if start is None or not (np.isfinite(start) and bounds[0] <= start <= bounds[1]):
        start = _scan_start(geometry, x, y, sig, e_y, mu, bounds)
    res = _least_squares(residual, (start, e_y, mu), bounds, (vary_e_y, vary_mu), scale_covar, what)
    best = res.values["eta2"]
    if not res.success or not np.isfinite(best):
        raise Eta2FitError(f"fit_eta2: fit failed ({res.message}) ({what})")

    chi_min, nfree = res.chisqr, res.nfree
    redchi = chi_min / nfree
    e_best, mu_best = res.values["e_y"], res.values["mu"]
    options = {"robust": robust, "errors": errors, "interval": interval, "scale_covar": scale_covar, "n": psi.size}
    errs, dof, delta = _fit_errors(res, residual, strata, level, options, what)

    if vary_e_y or vary_mu:

        def profile(h):
            import lmfit

            q = res.params.copy()
            q["eta2"].set(value=h, vary=False)
            r = lmfit.minimize(lambda p: residual(p["eta2"].value, p["e_y"].value, p["mu"].value), q, method="leastsq")
            return float(r.chisqr)
    else:

        def profile(h):
            r = residual(h, e_best, mu_best)
            return float(r @ r)

    if interval:
        ci_low, ci_high = (
            _profile_crossing(profile, best, errs["eta2"], chi_min, delta, bounds, d) for d in (-1.0, 1.0)
        )
    else:
        ci_low, ci_high = np.nan, np.nan
    return Eta2Fit(
        eta2=float(best),
        eta2_err=errs["eta2"],
        eta2_ci_low=float(ci_low),
        eta2_ci_high=float(ci_high),
        e_y=float(e_best),
        e_y_err=errs["e_y"],
        mu=float(mu_best),
        mu_err=errs["mu"],
        chisqr=chi_min,
        redchi=redchi,
        n=psi.size,
        nfree=nfree,
        dof=dof,
        robust=bool(robust),
        level=float(level),
        delta_chi2=delta,
        scale_covar=bool(scale_covar),
        success=bool(res.success),
        message=str(res.message),
    )


def _checked_inputs(psi, x, y, r_x, r_y, alpha, sigma, vary_e_y, vary_mu, what):
    """Check the inputs of :func:`fit_eta2` whole and return them as float arrays of psi's shape.

    Returns ``(x, y, r_x, r_y, alpha, sigma)``; sigma is ones when None (unweighted).
    """
    n = psi.size
    try:
        x, y = (np.asarray(a, dtype=float).ravel() for a in (x, y))
        r_x, r_y, alpha = (np.broadcast_to(np.asarray(a, dtype=float), psi.shape) for a in (r_x, r_y, alpha))
        sig = np.ones(n) if sigma is None else np.broadcast_to(np.asarray(sigma, dtype=float), psi.shape)
    except ValueError as exc:
        raise ValueError(f"fit_eta2: inputs do not match psi ({what}): {exc}") from None
    if x.size != n or y.size != n:
        raise ValueError(f"fit_eta2: psi, x and y must have the same length; got {n}, {x.size}, {y.size}")
    for name, a in (("psi", psi), ("x", x), ("y", y), ("r_x", r_x), ("r_y", r_y), ("sigma", sig)):
        if not np.all(np.isfinite(a)):
            raise ValueError(f"fit_eta2: {name} has non-finite values ({what})")
    if np.any(sig <= 0):
        raise ValueError(f"fit_eta2: sigma must be positive ({what})")
    nvary = 1 + int(vary_e_y) + int(vary_mu)
    if n <= nvary:
        raise ValueError(f"fit_eta2: need more than {nvary} impacts ({what})")
    return x, y, r_x, r_y, alpha, sig


class _Residual:
    """The weighted residual ``(y - (1 + e_x) x) / sigma`` of the impacts at (eta2, e_y, mu), and its calls.

    The model is evaluated on the impacts' :class:`ImpactGeometry` (prepared once per fit).
    lmfit asks for the residual at the same point more than once (its checks before the fit,
    MINPACK's first call and the result's residual): a call at a point already evaluated
    (scalar parameters equal to the bit) returns the stored residual, the same numbers,
    without running the model again. ``calls`` counts the model's evaluations.
    """

    def __init__(self, geometry: ImpactGeometry, x, y, sig) -> None:
        self.geometry, self.x, self.y, self.sig = geometry, x, y, sig
        self.seen: dict[tuple[float, float, float], np.ndarray] = {}
        self.calls = 0

    def __call__(self, eta2, e_y, mu) -> np.ndarray:
        key = None
        if np.ndim(eta2) == np.ndim(e_y) == np.ndim(mu) == 0:
            key = (float(eta2), float(e_y), float(mu))
            if key in self.seen:
                return self.seen[key].copy()
        self.calls += 1
        ex = self.geometry.e_x(eta2, e_y, mu)
        r = (self.y - (1.0 + ex) * self.x) / self.sig
        if key is not None:
            self.seen[key] = r.copy()
        return r


#: The values of eta^2 whose chi^2 is scanned for the fit's start (:func:`_scan_start`).
SCAN_POINTS = 48

#: The scan's coarse pass takes every SCAN_STRIDE-th value (and the last); the fine pass the values around its lowest.
#: 1: every value at once (the scan as it was; tests compare the two).
SCAN_STRIDE = 3


def _chi2_at(geometry: ImpactGeometry, x, y, sig, e_y, mu, eta2: np.ndarray) -> np.ndarray:
    """Return the chi^2 at each value of ``eta2`` (one call of the model: elementwise, as one call per value)."""
    res = (y - (1.0 + geometry.e_x(eta2[:, None], e_y, mu)) * x) / sig
    return np.array([float(r @ r) for r in res])


def _scan_start(geometry: ImpactGeometry, x, y, sig, e_y, mu, bounds: tuple[float, float]) -> float:
    """Return the starting eta^2: the lowest chi^2 of a logarithmic scan of ``bounds`` (:data:`SCAN_POINTS` values).

    In two passes: every :data:`SCAN_STRIDE`-th value of the scan (and its last), then the
    values within ``SCAN_STRIDE - 1`` of each of that pass's local minima; the start is the
    lowest chi^2 of all the values computed. chi^2 over the scan can have two minima (Omega_t
    near Omega_n, eta^2 about 1.2 and 3.2 for baseballs); every minimum whose dip spans a
    coarse step has a local minimum of the coarse pass next to it, so the start is the whole
    scan's lowest value, to the bit, from about 20 of its 48 (a dip narrower than that step,
    2 x 7.5 % in eta^2, would be missed: none in the tests and studies).
    """
    scan = np.geomspace(bounds[0], bounds[1], SCAN_POINTS)
    chi2 = np.full(scan.size, np.inf)
    coarse = np.unique(np.r_[np.arange(0, scan.size, SCAN_STRIDE), scan.size - 1])
    c = _chi2_at(geometry, x, y, sig, e_y, mu, scan[coarse])
    chi2[coarse] = c
    lower = np.r_[np.inf, c[:-1]], np.r_[c[1:], np.inf]  # each coarse value's neighbours
    minima = coarse[(c <= lower[0]) & (c <= lower[1])]
    near = np.unique(np.concatenate([np.arange(k - SCAN_STRIDE + 1, k + SCAN_STRIDE) for k in minima]))
    near = near[(near >= 0) & (near < scan.size) & ~np.isin(near, coarse)]
    if near.size:
        chi2[near] = _chi2_at(geometry, x, y, sig, e_y, mu, scan[near])
    return scan[int(np.argmin(chi2))]


def _lmfit_errors(params) -> dict[str, float]:
    """Return lmfit's standard error of each parameter (NaN where fixed or not estimated)."""

    def err(name):
        p = params[name]
        return float(p.stderr) if (p.vary and p.stderr is not None) else np.nan

    return {k: err(k) for k in ("eta2", "e_y", "mu")}


def _chi2_rise(level: float, scale: float) -> float:
    """Delta of the profile interval, not robust: ``chi2.ppf(level, 1)`` times ``scale``."""
    from scipy.stats import chi2

    return float(chi2.ppf(level, 1)) * scale


def _fit_errors(res: _LeastSquares, residual, strata, level: float, options: dict, what) -> tuple[dict, float, float]:
    """Return the standard errors, their degrees of freedom and the interval's chi^2 rise (``options``: fit_eta2's).

    ``errors=False``: NaN (and no interval); ``robust``: the sandwich (:func:`_robust_errors`);
    otherwise lmfit's, with n - p degrees of freedom.
    """
    if not options["errors"]:
        if options["interval"]:
            raise ValueError(f"fit_eta2: the profile interval needs the standard errors (errors=False) ({what})")
        return dict.fromkeys(("eta2", "e_y", "mu"), np.nan), np.nan, np.nan
    if options["robust"]:
        if strata is not None and np.shape(strata) != (options["n"],):
            raise ValueError(f"fit_eta2: strata must have one label per impact ({what})")
        return _robust_errors(res, residual, strata, level)
    redchi = res.chisqr / res.nfree
    return dict(res.stderr), float(res.nfree), _chi2_rise(level, redchi if options["scale_covar"] else 1.0)


def _robust_errors(res: _LeastSquares, residual, strata, level: float) -> tuple[dict[str, float], float, float]:
    """Sandwich standard errors, their Bell-McCaffrey dof and the chi^2 rise of the interval.

    The errors of the free parameters are the HC3 sandwich's centred within ``strata``; the
    rise is t_nu^2 times the ratio of the robust to the unscaled variance of eta^2.
    """
    from scipy.special import stdtrit  # Student's t quantile: scipy.stats.t.ppf's own, without its checks

    from ..linefit import sandwich_cov, sandwich_dof

    errs = dict(res.stderr)
    names = list(res.vary)
    J, r = _jacobian(residual, dict(res.values), names)
    cov = sandwich_cov(J, r, strata)
    errs.update({k: float(np.sqrt(cov[i, i])) for i, k in enumerate(names)})
    dof = sandwich_dof(J, strata, 0)
    var_unscaled = float(np.linalg.inv(J.T @ J)[0, 0])
    delta = float(stdtrit(dof, 0.5 + level / 2.0)) ** 2 * errs["eta2"] ** 2 / var_unscaled
    return errs, dof, delta


def _profile_crossing(profile, best, eta2_err, chi_min, delta, bounds: tuple[float, float], direction: float) -> float:
    """Where ``profile(eta2)`` rises ``delta`` above ``chi_min`` on one side of ``best``.

    Steps out from ``best`` by doubling steps (from the standard error, or 5 % of ``best``)
    until the rise is passed, then brackets the crossing (brentq). NaN if it stays below
    within ``bounds`` or 40 steps.
    """
    from scipy.optimize import brentq

    lo_b, hi_b = bounds
    step = eta2_err if np.isfinite(eta2_err) and eta2_err > 0 else 0.05 * best
    inner = best
    for _ in range(40):
        outer = best + direction * 2.0 * step
        outer = min(max(outer, lo_b), hi_b)
        if profile(outer) - chi_min > delta:
            return brentq(
                lambda h: profile(h) - chi_min - delta, min(inner, outer), max(inner, outer), xtol=1e-8 * best
            )
        if outer in (lo_b, hi_b):
            return np.nan
        inner, step = outer, 2.0 * step
    return np.nan
