"""Fits of Sec. IV: e_x per bat and ball (Eq. omega), Eq. ratio, and Figs. 3-4 slopes.

Every fit is a straight line fitted with lmfit. Measurement uncertainties enter through
the *effective variance* of each impact's residual: the abscissa and the ordinate are
both functions of the measured (v_bat, v_ball, theta, omega), so the residual
y - (a + s x) has variance sum_k (dy/dm_k - s dx/dm_k)^2 sigma_k^2 over the measured
quantities m_k (correlations between x and y through psi included). The weights depend
on the slope, so the fit is iterated (three passes converge to far below the standard
error). Standard errors are lmfit's, scaled by the reduced chi-square (as the paper's
standard errors come from the scatter of the data); the reduced chi-square itself tells
whether the stated measurement uncertainties explain that scatter. 95 % intervals use
Student's t with n - p degrees of freedom. Without uncertainties the fit is unweighted
and the reduced chi-square is undefined (NaN).

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017), Sec. IV.
.. [2] J. Orear, "Least squares when both variables have uncertainties",
   Am. J. Phys. 50, 912 (1982) (effective variance).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from .kinematics import V_BAT_REF, e_y_from_tan_ratio_slope, gross_slip_onset

#: The measured quantities, in the order of the Jacobian columns.
MEASURED = ("v_bat", "v_ball", "theta", "omega")

#: Fewest usable impacts for a fit of e_x per bat or pooled; fewer give NaN with n and a note.
MIN_FIT_IMPACTS = 3


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

    def as_dict(self) -> dict:
        return asdict(self)


NAN_FIT = LineFit(np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, 0, np.nan, False)


def _line(x, slope, intercept=0.0):
    return intercept + slope * x


def fit_line(x, y, jx=None, jy=None, sigma=None, through_origin=True, iterations=3) -> LineFit:
    """Fit y = slope x (+ intercept) with lmfit, weighting by the effective variance.

    Parameters
    ----------
    x, y : (n,) arrays.
    jx, jy : (n, k) partial derivatives of x and y with respect to the k measured
        quantities; ``sigma`` (n, k) their standard uncertainties. All three or none.
    through_origin : fit y = slope x (Eq. omega, Eq. ratio) or a line with intercept.
    """
    import lmfit
    from scipy import stats

    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    n = x.size
    p = 1 if through_origin else 2
    if n <= p:
        return LineFit(np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, n, np.nan, False)
    model = lmfit.Model(_line, independent_vars=["x"])
    params = model.make_params(slope=1.0, intercept=0.0)
    if through_origin:
        params["intercept"].set(value=0.0, vary=False)
    weighted = sigma is not None and np.all(np.isfinite(sigma)) and np.any(np.asarray(sigma) > 0)
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
        return LineFit(np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, n, np.nan, False)
    slope = float(result.params["slope"].value)
    err = float(result.params["slope"].stderr)
    tq = float(stats.t.ppf(0.975, n - p))
    icpt = 0.0 if through_origin else float(result.params["intercept"].value)
    icpt_err = 0.0 if through_origin else float(result.params["intercept"].stderr)
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


def wls_slope(x, y, weights=None, through_origin=True) -> tuple[float, float]:
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


# ---------------------------------------------------------------------------------------
# Designs: abscissa, ordinate and their derivatives with respect to (v_bat, v_ball, theta, omega)


def _psi_and_partials(v_ball, theta, omega, r, alpha):
    """psi of Eq. angmom and d psi / d(v_bat, v_ball, theta, omega)."""
    q = alpha * r * omega / v_ball
    root = np.sqrt(1.0 - q**2)
    psi = theta + np.arcsin(q)
    d = np.stack([np.zeros_like(q), -q / (v_ball * root), np.ones_like(q), alpha * r / (v_ball * root)], axis=1)
    return psi, d


def spin_design(v_bat, v_ball, theta, omega, r, r_x, alpha):
    """Eq. omega: x = v_bat sin psi / (r (1 + r_x)(1 + alpha)), y = omega."""
    psi, dpsi = _psi_and_partials(v_ball, theta, omega, r, alpha)
    c = 1.0 / (r * (1.0 + r_x) * (1.0 + alpha))
    x = v_bat * np.sin(psi) * c
    jx = (v_bat * np.cos(psi) * c)[:, None] * dpsi
    jx[:, 0] += np.sin(psi) * c
    jy = np.zeros_like(jx)
    jy[:, 3] = 1.0
    return x, omega, jx, jy


def tan_ratio_design(v_bat, v_ball, theta, omega, r, alpha):
    """Eq. ratio: x = tan psi, y = tan(psi - theta) = q / sqrt(1 - q^2), q = alpha r omega / v_ball."""
    psi, dpsi = _psi_and_partials(v_ball, theta, omega, r, alpha)
    q = alpha * r * omega / v_ball
    x = np.tan(psi)
    y = q / np.sqrt(1.0 - q**2)
    jx = (1.0 / np.cos(psi) ** 2)[:, None] * dpsi
    dydq = (1.0 - q**2) ** -1.5
    jy = np.zeros_like(jx)
    jy[:, 1] = -dydq * q / v_ball
    jy[:, 3] = dydq * alpha * r / v_ball
    return x, y, jx, jy


def vtf_design(v_bat, v_ball, theta, omega, r, r_x, alpha):
    """Eq. vtf: x = tan psi / (1 + r_x), y = (v_ball,t + r omega) / v_bat,n.

    With Eq. angmom, v_ball,t = alpha r omega, so y = (1 + alpha) r omega / (v_bat cos psi).
    """
    psi, dpsi = _psi_and_partials(v_ball, theta, omega, r, alpha)
    x = np.tan(psi) / (1.0 + r_x)
    y = (1.0 + alpha) * r * omega / (v_bat * np.cos(psi))
    jx = (1.0 / (np.cos(psi) ** 2 * (1.0 + r_x)))[:, None] * dpsi
    jy = (y * np.tan(psi))[:, None] * dpsi
    jy[:, 0] += -y / v_bat
    jy[:, 3] += (1.0 + alpha) * r / (v_bat * np.cos(psi))
    return x, y, jx, jy


def effective_sigma(jx, jy, sigma, slope):
    """Standard deviation of y - slope x from the measurement uncertainties (effective variance)."""
    if sigma is None:
        return None
    return np.sqrt(np.sum((jy - slope * jx) ** 2 * sigma**2, axis=1))


def normalized_theta_design(v_bat, value, theta, which, v_ref=V_BAT_REF):
    """Figs. 3-4: x = theta, y = value v_ref / v_bat, value = omega or v_ball."""
    n = np.size(theta)
    y = value * v_ref / v_bat
    jx = np.zeros((n, 4))
    jx[:, 2] = 1.0
    jy = np.zeros((n, 4))
    jy[:, 0] = -y / v_bat
    jy[:, MEASURED.index(which)] = v_ref / v_bat
    return theta, y, jx, jy


# ---------------------------------------------------------------------------------------
# The Sec. IV analysis of one dataset


def _measured(ds, sel, prefix=""):
    return [np.asarray(ds[prefix + k].values[sel], dtype=float) for k in MEASURED]


def _sigma(ds, sel):
    if all(f"{k}_err" in ds for k in MEASURED):
        return np.stack([ds[f"{k}_err"].values[sel] for k in MEASURED], axis=1).astype(float)
    return None


def _weights(jx, jy, sigma, slope):
    if sigma is None or not np.isfinite(slope):
        return None
    var = np.sum((jy - slope * jx) ** 2 * sigma**2, axis=1)
    return 1.0 / np.sqrt(var) if np.all(var > 0) else None


def _fit_note(fit: LineFit) -> str:
    """Why a fit of e_x has no value ('ok' when it has one)."""
    if fit.n < MIN_FIT_IMPACTS:
        return f"not fitted: {fit.n} usable impact(s), fewer than {MIN_FIT_IMPACTS}"
    return "ok" if fit.success else "fit failed"


def analyze_impacts(ds, v_ref=V_BAT_REF, mu_k_example=0.5) -> dict:
    """Sec. IV analysis of a reconstructed dataset (output of ``analysis.reconstruct``).

    Uses only impacts with ``flag == 0``. Returns a dict of results keyed by quantity,
    each a dict keyed by ``ball`` or ``(ball, bat)`` of :class:`LineFit` or floats.
    When the dataset holds ``truth_*`` variables (synthetic), each quantity also gets a
    truth value: the same estimator applied to the noise-free truth with the same weights.
    """
    usable = ds["flag"].values == 0
    balls = ds["ball"].values.astype(str)
    bats = ds["bat"].values.astype(str)
    has_truth = all(f"truth_{k}" in ds for k in MEASURED)
    res: dict = {
        "e_x": {},
        "e_x_pooled": {},
        "tan_ratio_slope": {},
        "e_y_implied": {},
        "mu_k_lower_bound": {},
        "spin_theta_slope": {},
        "speed_theta_slope": {},
        "gross_slip": {},
        "truth": {},
        "e_x_note": {},
        "e_x_pooled_note": {},
    }
    truth = res["truth"]

    def spin_fit(sel):
        n = int(np.sum(sel))
        if n < MIN_FIT_IMPACTS:  # too few for a slope and its error: report, do not fit
            return LineFit(np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, n, np.nan, False), np.nan
        r, r_x, alpha = (ds[k].values[sel] for k in ("r", "r_x", "alpha"))
        x, y, jx, jy = spin_design(*_measured(ds, sel), r, r_x, alpha)
        sig = _sigma(ds, sel)
        fit = fit_line(x, y, jx, jy, sig)
        t = np.nan
        if has_truth and fit.success:
            xt, yt, _, _ = spin_design(*_measured(ds, sel, "truth_"), r, r_x, alpha)
            t = wls_slope(xt, yt, _weights(jx, jy, sig, fit.slope))[0] - 1.0
        return fit, t

    for ball in sorted(set(balls)):
        in_ball = usable & (balls == ball)
        for bat in sorted(set(bats[balls == ball])):
            sel = in_ball & (bats == bat)
            fit, t = spin_fit(sel)
            res["e_x"][(ball, bat)] = fit
            res["e_x_note"][(ball, bat)] = _fit_note(fit)
            truth[("e_x", ball, bat)] = t
        fit, t = spin_fit(in_ball)
        res["e_x_pooled"][ball] = fit
        res["e_x_pooled_note"][ball] = _fit_note(fit)
        truth[("e_x_pooled", ball)] = t
        if int(in_ball.sum()) < MIN_FIT_IMPACTS:  # per-ball fits need the same minimum: report NaN
            nan_fit = LineFit(np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, int(in_ball.sum()), np.nan, False)
            for key in ("tan_ratio_slope", "spin_theta_slope", "speed_theta_slope"):
                res[key][ball] = nan_fit
            res["e_y_implied"][ball] = (np.nan, np.nan)
            res["mu_k_lower_bound"][ball] = (np.nan, np.nan, -1)
            res["gross_slip"][ball] = (np.nan, np.nan, np.nan)
            continue

        r, r_x, r_y, alpha = (ds[k].values[in_ball] for k in ("r", "r_x", "r_y", "alpha"))
        x, y, jx, jy = tan_ratio_design(*_measured(ds, in_ball), r, alpha)
        sig = _sigma(ds, in_ball)
        rfit = fit_line(x, y, jx, jy, sig)
        res["tan_ratio_slope"][ball] = rfit
        # Eq. ratio inverted with the pooled e_x and the mean recoil factors of the impacts.
        exf = res["e_x_pooled"][ball]
        a = float(np.mean(alpha))
        e_y = e_y_from_tan_ratio_slope(rfit.slope, exf.slope - 1.0, np.mean(r_x), np.mean(r_y), a)
        e_y_err = (1.0 + e_y) * np.hypot(rfit.slope_err / rfit.slope, exf.slope_err / exf.slope)
        res["e_y_implied"][ball] = (float(e_y), float(e_y_err))
        # Eq. muk: the largest measured tan(psi - theta) bounds mu_k from below.
        if y.size:
            i = int(np.nanargmax(y))
            err = float(np.sqrt(np.sum(jy[i] ** 2 * sig[i] ** 2))) if sig is not None else np.nan
            res["mu_k_lower_bound"][ball] = (float(y[i]), err, int(ds["impact"].values[in_ball][i]))
        else:
            res["mu_k_lower_bound"][ball] = (np.nan, np.nan, -1)
        psi_g, theta_g, omega_g = gross_slip_onset(
            mu_k_example, rfit.slope, v_ref, exf.slope - 1.0, float(np.mean(r)), float(np.mean(r_x)), a
        )
        res["gross_slip"][ball] = (float(psi_g), float(theta_g), float(omega_g))
        if has_truth:
            xt, yt, _, _ = tan_ratio_design(*_measured(ds, in_ball, "truth_"), r, alpha)
            truth[("tan_ratio_slope", ball)] = wls_slope(xt, yt, _weights(jx, jy, sig, rfit.slope))[0]
            truth[("e_y_implied", ball)] = float(np.mean(ds["truth_e_y"].values[in_ball]))
            truth[("mu_k_lower_bound", ball)] = float(np.max(yt)) if yt.size else np.nan

        v_bat, v_ball, theta, omega = _measured(ds, in_ball)
        for key, value, which in (
            ("spin_theta_slope", omega, "omega"),
            ("speed_theta_slope", v_ball, "v_ball"),
        ):
            x, y, jx, jy = normalized_theta_design(v_bat, value, theta, which, v_ref)
            fit = fit_line(x, y, jx, jy, sig, through_origin=False)
            res[key][ball] = fit
            if has_truth:
                tv = _measured(ds, in_ball, "truth_")
                xt, yt, _, _ = normalized_theta_design(tv[0], tv[MEASURED.index(which)], tv[2], which, v_ref)
                truth[(key, ball)] = wls_slope(xt, yt, _weights(jx, jy, sig, fit.slope), through_origin=False)[0]
    return res


def _fit_vars(name, fits, dims, coords, units, what, truth=None):
    """NetCDF variables of a family of LineFits indexed like ``coords``."""
    shape = tuple(len(coords[d]) for d in dims)
    arrs = {k: np.full(shape, np.nan) for k in ("value", "err", "lo", "hi", "icpt", "icpt_err", "redchi", "truth")}
    n = np.zeros(shape, dtype=np.int64)
    for key, fit in fits.items():
        idx = tuple(coords[d].index(k) for d, k in zip(dims, key if isinstance(key, tuple) else (key,), strict=True))
        arrs["value"][idx], arrs["err"][idx] = fit.slope, fit.slope_err
        arrs["lo"][idx], arrs["hi"][idx] = fit.slope_ci_low, fit.slope_ci_high
        arrs["icpt"][idx], arrs["icpt_err"][idx] = fit.intercept, fit.intercept_err
        arrs["redchi"][idx], n[idx] = fit.redchi, fit.n
        if truth is not None:
            arrs["truth"][idx] = truth.get(key, np.nan)
    out = {
        name: (dims, arrs["value"], {"units": units, "long_name": what}),
        f"{name}_err": (dims, arrs["err"], {"units": units, "long_name": f"standard error of {what}"}),
        f"{name}_ci_low": (
            dims,
            arrs["lo"],
            {"units": units, "long_name": f"lower end of the 95 % confidence interval of {what}"},
        ),
        f"{name}_ci_high": (
            dims,
            arrs["hi"],
            {"units": units, "long_name": f"upper end of the 95 % confidence interval of {what}"},
        ),
        f"{name}_n": (dims, n, {"units": "1", "long_name": f"number of impacts in the fit of {what}"}),
        f"{name}_redchi": (
            dims,
            arrs["redchi"],
            {"units": "1", "long_name": f"reduced chi-square of the fit of {what}"},
        ),
    }
    if truth is not None:
        out[f"truth_{name}"] = (
            dims,
            arrs["truth"],
            {
                "units": units,
                "long_name": f"true {what} (same estimator on the noise-free truth)",
                "ballbat_role": "truth",
            },
        )
    return out


def results_dataset(res: dict, has_truth: bool, mu_k_example: float):
    """The Sec. IV results of :func:`analyze_impacts` as an xarray Dataset (dims ball, bat)."""
    import xarray as xr

    balls = sorted(res["e_x_pooled"])
    bats = sorted({bat for _, bat in res["e_x"]})
    coords = {"ball": balls, "bat": bats}
    tr = res["truth"]

    def truth_for(q):
        if not has_truth:
            return None
        return {k[1:] if len(k) > 2 else k[1]: v for k, v in tr.items() if k[0] == q}

    # e_x = slope - 1 for the Eq. omega fits.
    def shift(fits):
        return {
            k: LineFit(
                f.slope - 1,
                f.slope_err,
                f.slope_ci_low - 1,
                f.slope_ci_high - 1,
                f.intercept,
                f.intercept_err,
                f.n,
                f.redchi,
                f.success,
            )
            for k, f in fits.items()
        }

    data = {}
    data.update(
        _fit_vars(
            "e_x",
            shift(res["e_x"]),
            ("ball", "bat"),
            coords,
            "1",
            "tangential coefficient of restitution e_x per bat and ball (Eq. omega)",
            truth_for("e_x"),
        )
    )
    data.update(
        _fit_vars(
            "e_x_pooled",
            shift(res["e_x_pooled"]),
            ("ball",),
            coords,
            "1",
            "tangential coefficient of restitution e_x pooled over bats (Eq. ex, Fig. 5)",
            truth_for("e_x_pooled"),
        )
    )
    data.update(
        _fit_vars(
            "tan_ratio_slope",
            res["tan_ratio_slope"],
            ("ball",),
            coords,
            "1",
            "slope of tan(psi - theta) against tan psi (Eq. ratio, Fig. 6)",
            truth_for("tan_ratio_slope"),
        )
    )
    data.update(
        _fit_vars(
            "spin_theta_slope",
            res["spin_theta_slope"],
            ("ball",),
            coords,
            "rad s-1 rad-1",
            "slope of normalised spin against theta (Fig. 3)",
            truth_for("spin_theta_slope"),
        )
    )
    data.update(
        _fit_vars(
            "speed_theta_slope",
            res["speed_theta_slope"],
            ("ball",),
            coords,
            "m s-1 rad-1",
            "slope of normalised exit speed against theta (Fig. 4)",
            truth_for("speed_theta_slope"),
        )
    )
    for name in ("spin_theta_slope", "speed_theta_slope"):
        units = data[name][2]["units"].replace(" rad-1", "")
        data[f"{name}_intercept"] = (
            ("ball",),
            np.array([res[name][b].intercept for b in balls]),
            {"units": units, "long_name": f"intercept at theta = 0 of the fit of {name}"},
        )
    for name, dims in (("e_x", ("ball", "bat")), ("e_x_pooled", ("ball",))):
        note = np.full(tuple(len(coords[d]) for d in dims), "no impacts", dtype=object)
        for key, text in res.get(f"{name}_note", {}).items():
            keys = key if isinstance(key, tuple) else (key,)
            note[tuple(coords[d].index(k) for d, k in zip(dims, keys, strict=True))] = text
        data[f"{name}_note"] = (dims, note.astype(str), {"long_name": f"why {name} has no value (ok if it has one)"})
    ey = np.array([res["e_y_implied"][b] for b in balls])
    data["e_y_implied"] = (
        ("ball",),
        ey[:, 0],
        {
            "units": "1",
            "long_name": "normal COR e_y implied by the Eq. ratio slope and pooled e_x (mean r_x, r_y)",
        },
    )
    data["e_y_implied_err"] = (
        ("ball",),
        ey[:, 1],
        {"units": "1", "long_name": "standard error of e_y implied (slope and e_x errors, uncorrelated)"},
    )
    mk = np.array([res["mu_k_lower_bound"][b] for b in balls])
    data["mu_k_lower_bound"] = (
        ("ball",),
        mk[:, 0],
        {"units": "1", "long_name": "lower bound on mu_k: largest tan(psi - theta) (Eq. muk)"},
    )
    data["mu_k_lower_bound_err"] = (
        ("ball",),
        mk[:, 1],
        {"units": "1", "long_name": "measurement uncertainty of that largest tan(psi - theta)"},
    )
    data["mu_k_lower_bound_impact"] = (
        ("ball",),
        mk[:, 2].astype(np.int64),
        {"units": "1", "long_name": "impact number of the largest tan(psi - theta)"},
    )
    gs = np.array([res["gross_slip"][b] for b in balls])
    for i, (nm, units, what) in enumerate(
        (
            ("psi", "rad", "impact angle psi"),
            ("theta", "rad", "angle theta"),
            ("omega", "rad s-1", "spin at the reference bat speed"),
        )
    ):
        data[f"gross_slip_{nm}"] = (
            ("ball",),
            gs[:, i],
            {
                "units": units,
                "long_name": f"{what} where gross slip sets in for mu_k = {mu_k_example} (Sec. IV)",
            },
        )
    if has_truth:
        for q in ("e_y_implied", "mu_k_lower_bound"):
            data[f"truth_{q}"] = (
                ("ball",),
                np.array([tr.get((q, b), np.nan) for b in balls]),
                {"units": "1", "long_name": f"true {q.replace('_', ' ')}", "ballbat_role": "truth"},
            )
    ds = xr.Dataset(
        data,
        coords={
            "ball": ("ball", np.array(balls, dtype=str), {"long_name": "ball type"}),
            "bat": ("bat", np.array(bats, dtype=str), {"long_name": "bat"}),
        },
    )
    ds.attrs["mu_k_example"] = float(mu_k_example)
    return ds


def fit_dataset(impacts, v_ref=V_BAT_REF, mu_k_example=0.5):
    """The Sec. IV fits of a reconstructed dataset, as a Dataset ready to write."""
    res = analyze_impacts(impacts, v_ref=v_ref, mu_k_example=mu_k_example)
    has_truth = all(f"truth_{k}" in impacts for k in MEASURED)
    ds = results_dataset(res, has_truth, mu_k_example)
    ds.attrs["n_impacts"] = int(impacts.sizes["impact"])
    ds.attrs["n_excluded"] = int((impacts["flag"].values != 0).sum())
    return ds
