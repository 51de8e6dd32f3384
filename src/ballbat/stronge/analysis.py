"""Stronge's contact model applied to a dataset (Sec. V.A): the eta^2 fit and Figs. 9-10.

For each ball the Eq. vtf data of the usable impacts (``flag == 0``) are fitted with
Stronge's lumped-parameter model in the bat frame, each impact with its own recoil
factors (:func:`ballbat.stronge.fit.fit_eta2`). The result holds the fitted parameters and
intervals, the model curves on a psi grid (Fig. 9a and its extrapolation, Fig. 9b) for the
fitted and for the published eta^2, the time histories at psi_history (Fig. 10) and the
regime boundaries in psi.

The compute functions (:func:`vtf_data`, :func:`model_curves`, :func:`boundaries`,
:func:`time_history`, :func:`analyse_ball`) return arrays and small dataclasses;
:func:`stronge_variables` declares the file ``results/{dataset}/stronge.nc`` once and
:func:`stronge_dataset` fills it.

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017), Sec. V.A.
.. [2] W. J. Stronge, Impact Mechanics (Cambridge University Press, 2000).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from operator import attrgetter

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from ..designs import Measured, measured_sigma, vtf_design
from ..linefit import MIN_FIT_IMPACTS, effective_sigma, wls_slope
from ..pipeline.products import Var, build_dataset, carried_warnings, estimate_vars, flag_attrs
from ..published import STRONGE_E_Y, STRONGE_MU, per_ball
from .fit import Eta2Fit, fit_eta2
from .model import ContactParams, omega_ratio, stronge_ex, stronge_solve
from .regimes import Regime, regime_boundaries

__all__ = [
    "PUBLISHED_ETA2",
    "BallAnalysis",
    "Boundaries",
    "History",
    "ModelCurves",
    "VtfData",
    "analyse_ball",
    "boundaries",
    "fit_ball",
    "model_curves",
    "stronge_dataset",
    "stronge_variables",
    "time_history",
    "vtf_data",
]

#: eta^2 published in Sec. V.A (with e_y = mu = 0.5), drawn beside the fits.
PUBLISHED_ETA2 = per_ball("eta2")

#: The histories of Fig. 10, in the order of :class:`History` (name -> what, scaled).
HISTORY_VARIABLES = {
    "normal_force": "normal force / peak normal force",
    "tangential_force": "tangential spring force / peak normal force",
    "tangential_velocity": "tangential velocity of the ball's contact point / initial normal speed",
    "spring_stretch": "tangential spring stretch / (v_n / Omega_n)",
    "stick": "1 while the contact point sticks, 0 while it slips (NaN after separation)",
}


# --------------------------------------------------------------------------------------
# compute
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class VtfData:
    """The Eq. vtf data of one ball's usable impacts (what the eta^2 fit sees).

    Attributes
    ----------
    psi : incidence angle of each impact, rad.
    x, y : ``tan(psi)/(1 + r_x)`` and ``(v_ball,t + r omega)/v_bat,n`` (Eq. vtf).
    sigma : effective standard uncertainty of y, or None when the file gives none.
    r_x, r_y, alpha : recoil factors of each impact's bat and I/(m r^2) of the ball.
    bat : each impact's bat (the strata of the standard error).
    """

    psi: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    sigma: NDArray[np.float64] | None
    r_x: NDArray[np.float64]
    r_y: NDArray[np.float64]
    alpha: NDArray[np.float64]
    bat: NDArray[np.str_]


def vtf_data(rec: xr.Dataset, sel: NDArray[np.bool_]) -> VtfData:
    """Eq. vtf data and their effective uncertainties for the impacts ``sel`` of ``rec``.

    Parameters
    ----------
    rec : xarray.Dataset
        Reconstructed impacts (``results/{dataset}/reconstruct.nc``).
    sel : ndarray of bool
        The impacts to use (one ball's usable impacts).

    Returns
    -------
    VtfData
        ``sigma`` is None unless ``rec`` holds ``*_err`` of every measured quantity; then it is
        the effective standard uncertainty of ``y - (1 + e_x) x`` with the local slope of the
        data (the model's slope varies slowly with psi over the experiment's range).
    """
    r, r_x, r_y, alpha = (rec[k].values[sel] for k in ("r", "r_x", "r_y", "alpha"))
    x, y, jx, jy = vtf_design(Measured.from_dataset(rec, sel), r, r_x, alpha)
    sig = measured_sigma(rec, sel)
    sigma = None if sig is None else effective_sigma(jx, jy, sig, wls_slope(x, y)[0])
    return VtfData(rec["psi"].values[sel], x, y, sigma, r_x, r_y, alpha, rec["bat"].values[sel].astype(str))


@dataclass(frozen=True)
class ModelCurves:
    """Eq. vtf curves of the model on a psi grid: abscissa, e_x and ordinate (1 + e_x) x."""

    vtf_x: NDArray[np.float64]
    e_x: NDArray[np.float64]
    vtf_y: NDArray[np.float64]


def model_curves(psi_grid: NDArray[np.float64], contact: ContactParams) -> ModelCurves:
    """Evaluate the model's Eq. vtf curve (Fig. 9) for one set of parameters.

    Parameters
    ----------
    psi_grid : ndarray
        Incidence angles, rad.
    contact : ContactParams
        The model's parameters, scalars (here the ball's mean recoil factors).

    Returns
    -------
    ModelCurves
        ``vtf_x = tan(psi)/(1 + r_x)``, ``e_x`` of the model, ``vtf_y = (1 + e_x) vtf_x``.
    """
    x = np.tan(psi_grid) / (1.0 + contact.r_x)
    ex = stronge_ex(psi_grid, contact)
    return ModelCurves(x, ex, (1.0 + ex) * x)


@dataclass(frozen=True)
class Boundaries:
    """Regime boundaries in psi (rad): the solver's first ones and the paper's formulas.

    ``psi_stick`` is where an initial stick first ends (NaN: none found), ``psi_gross_slip``
    where gross slip first begins; ``psi_stick_paper = atan(mu eta^2)`` and
    ``psi_gross_slip_paper = atan(3.5 mu (1 + e_y))`` are the statements of Sec. V.A.
    """

    psi_stick: float
    psi_gross_slip: float
    psi_stick_paper: float
    psi_gross_slip_paper: float


def boundaries(contact: ContactParams) -> Boundaries:
    """Regime boundaries of the model for one ball (Fig. 9b's vertical lines).

    Parameters
    ----------
    contact : ContactParams
        As in :func:`ballbat.stronge.regimes.regime_boundaries`.

    Returns
    -------
    Boundaries
    """
    rb = regime_boundaries(contact)
    stick = [p for p, b in zip(rb.psi, rb.below, strict=True) if str(b).startswith("stick")]
    gross = [p for p, ab in zip(rb.psi, rb.above, strict=True) if ab == "gross-slip"]
    return Boundaries(
        stick[0] if stick else np.nan, gross[0] if gross else np.nan, rb.psi_stick_paper, rb.psi_gross_paper
    )


@dataclass(frozen=True)
class History:
    """Time histories of one impact (Fig. 10) and its event times, in units of t_c.

    The arrays are sampled on ``t`` (t/t_c) and NaN after separation; ``stick`` is 1 while
    the contact point sticks and 0 while it slips.
    """

    t: NDArray[np.float64]
    normal_force: NDArray[np.float64]
    tangential_force: NDArray[np.float64]
    tangential_velocity: NDArray[np.float64]
    spring_stretch: NDArray[np.float64]
    stick: NDArray[np.float64]
    t_stick_end: float
    t_separation: float
    t_stretch_max: float
    regime: Regime
    n_phases: int


def time_history(psi: float, contact: ContactParams, n_time: int, t_max: float | None = None) -> History:
    """Compute forces, tangential velocity, stretch and stick of one impact against t/t_c (Fig. 10).

    Parameters
    ----------
    psi : float
        Incidence angle, rad.
    contact : ContactParams
        The model's parameters, scalars.
    n_time : int
        Number of samples from t = 0 to ``t_max``.
    t_max : float, optional
        End of the samples, t/t_c (default: separation, 1 + e_y).

    Returns
    -------
    History
    """
    sol = stronge_solve(psi, contact, histories=True, n_time=n_time, t_max=t_max)
    stuck = np.where(np.isfinite(sol.normal_force), (np.abs(sol.c_velocity) < 1e-12).astype(float), np.nan)
    return History(
        t=sol.t,
        normal_force=sol.normal_force,
        tangential_force=sol.tangential_force,
        tangential_velocity=sol.u,
        spring_stretch=sol.stretch,
        stick=stuck,
        t_stick_end=float(sol.t_stick_end),
        t_separation=float(sol.t_separation),
        t_stretch_max=float(sol.t_stretch_max),
        regime=Regime.from_label(str(sol.regime)),
        n_phases=int(sol.n_phases),
    )


@dataclass(frozen=True)
class BallAnalysis:
    """The fit of one ball and the model evaluated at it (all but the time histories).

    ``params`` are the model's parameters at the fit: eta2, e_y, mu and the mean r_x, r_y
    and alpha of the ball's impacts (bat frame).
    """

    fit: Eta2Fit
    data: VtfData
    r_x_mean: float
    r_y_mean: float
    alpha_mean: float
    omega_ratio: float
    omega_ratio_bat: float
    model: ModelCurves
    eta2_published: float
    published: ModelCurves | None
    boundaries: Boundaries

    @property
    def params(self) -> ContactParams:
        """The model's parameters at the fit."""
        return ContactParams(self.fit.eta2, self.fit.e_y, self.fit.mu, self.r_x_mean, self.r_y_mean, self.alpha_mean)


def fit_ball(
    data: VtfData,
    *,
    e_y: float,
    mu: float,
    vary_e_y: bool,
    vary_mu: bool,
    sigma: NDArray[np.float64] | None = None,
    interval: bool = True,
) -> Eta2Fit:
    """Fit eta^2 to one ball's Eq. vtf data as the workflow does (the workflow and the replicate studies).

    The standard error is the sandwich centred within bats, with Bell-McCaffrey degrees of
    freedom (:func:`ballbat.stronge.fit.fit_eta2` with ``robust=True``, ``strata`` the bats):
    a lab chooses its bats and the impacts per bat, so the misfit of one eta^2 to a bat's own
    e_x is the same in every repetition of the experiment; only the scatter within a bat is.

    Parameters
    ----------
    data : VtfData
        The ball's data (:func:`vtf_data`).
    e_y, mu : float
        Fixed values, or starting values when ``vary_e_y``/``vary_mu``.
    vary_e_y, vary_mu : bool
        Fit e_y and/or mu along with eta^2.
    sigma : ndarray, optional
        Weights' uncertainties in place of ``data.sigma`` (the truth of a replicate study
        is fitted with the measured data's weights).
    interval : compute the profile-likelihood interval (the truth of a study needs the value only).

    Returns
    -------
    Eta2Fit
    """
    d = data
    return fit_eta2(
        d.psi,
        d.x,
        d.y,
        d.r_x,
        d.r_y,
        sigma=d.sigma if sigma is None else sigma,
        e_y=e_y,
        mu=mu,
        alpha=d.alpha,
        vary_e_y=vary_e_y,
        vary_mu=vary_mu,
        robust=True,
        strata=d.bat,
        interval=interval,
    )


def analyse_ball(
    data: VtfData,
    eta2_published: float | None,
    psi_grid: NDArray[np.float64],
    *,
    e_y: float,
    mu: float,
    vary_e_y: bool,
    vary_mu: bool,
) -> BallAnalysis:
    """Fit eta^2 to one ball's data and evaluate the model at the fit (and at the paper's eta^2).

    Parameters
    ----------
    data : VtfData
        The ball's Eq. vtf data (:func:`vtf_data`).
    eta2_published : float or None
        The paper's eta^2 for this ball (curves drawn with the paper's e_y and mu), if any.
    psi_grid : ndarray
        Incidence angles of the model curves, rad.
    e_y, mu : float
        Fixed values, or starting values when ``vary_e_y``/``vary_mu``.
    vary_e_y, vary_mu : bool
        Fit e_y and/or mu along with eta^2.

    Returns
    -------
    BallAnalysis
        Curves and boundaries use the mean recoil factors of the ball's impacts
        (bat frame) and the mean alpha.
    """
    d = data
    fit = fit_ball(d, e_y=e_y, mu=mu, vary_e_y=vary_e_y, vary_mu=vary_mu)
    a = float(np.mean(d.alpha))
    rxm, rym = float(np.mean(d.r_x)), float(np.mean(d.r_y))
    params = ContactParams(fit.eta2, fit.e_y, fit.mu, rxm, rym, a)
    published = None
    if eta2_published is not None:
        published = model_curves(psi_grid, ContactParams(eta2_published, STRONGE_E_Y, STRONGE_MU, rxm, rym, a))
    return BallAnalysis(
        fit=fit,
        data=d,
        r_x_mean=rxm,
        r_y_mean=rym,
        alpha_mean=a,
        omega_ratio=float(omega_ratio(fit.eta2, 0.0, 0.0, a)),
        omega_ratio_bat=float(params.omega_ratio()),
        model=model_curves(psi_grid, params),
        eta2_published=np.nan if eta2_published is None else float(eta2_published),
        published=published,
        boundaries=boundaries(params),
    )


# --------------------------------------------------------------------------------------
# the file: one declared table of variables
# --------------------------------------------------------------------------------------
def _column(items: list, name: str) -> NDArray:
    """``attrgetter(name)`` of every item, stacked (one row per ball)."""
    return np.array([attrgetter(name)(i) for i in items])


def _with(var: Var, **attrs: object) -> Var:
    return replace(var, attrs={**var.attrs, **attrs})


def stronge_variables(vary_e_y: bool = False, vary_mu: bool = False) -> dict[str, Var]:
    """Declare the data variables of ``results/{dataset}/stronge.nc``: name -> dims, units, long_name.

    Parameters
    ----------
    vary_e_y, vary_mu : bool
        Whether e_y and mu were fitted (recorded in their ``vary`` attribute).

    Returns
    -------
    dict of str to Var
        Dimensions: ``ball``; ``psi_grid`` (model curves); ``sample`` (time histories, with
        the auxiliary coordinate ``t_over_tc``); ``impact_fit`` (the fitted data).
    """
    b, bg, bs, fi = ("ball",), ("ball", "psi_grid"), ("ball", "sample"), ("impact_fit",)
    eta2 = estimate_vars("eta2", b, "1", "eta^2 = k_n/k_t fitted to Eq. vtf (Sec. V.A)")
    eta2["eta2_err"] = replace(eta2["eta2_err"], long_name="standard error of eta^2 (HC3 sandwich centred within bats)")
    for end in ("low", "high"):
        v = eta2[f"eta2_ci_{end}"]
        eta2[f"eta2_ci_{end}"] = replace(
            v, long_name=f"{'lower' if end == 'low' else 'upper'} end of the 95 % profile-likelihood interval of eta^2"
        )
    eta2["eta2_dof"] = Var(b, "1", "degrees of freedom of eta2_err (Bell-McCaffrey), for Student's t intervals")
    eta2["eta2"] = _with(eta2["eta2"], ancillary_variables=eta2["eta2"].attrs["ancillary_variables"] + " eta2_dof")
    e_y = estimate_vars("e_y", b, "1", "normal COR e_y of the model (fixed unless fitted)", fit=False, interval=False)
    e_y["e_y"] = _with(e_y["e_y"], vary=int(vary_e_y))
    e_y["e_y_err"] = replace(e_y["e_y_err"], long_name="standard error of e_y (NaN when fixed)")
    mu = estimate_vars(
        "mu", b, "1", "friction coefficient mu of the model (fixed unless fitted)", fit=False, interval=False
    )
    mu["mu"] = _with(mu["mu"], vary=int(vary_mu))
    mu["mu_err"] = replace(mu["mu_err"], long_name="standard error of mu (NaN when fixed)")
    paper = f"published eta^2, e_y = {STRONGE_E_Y:g}, mu = {STRONGE_MU:g}"
    return {
        **eta2,
        "eta2_published": Var(b, "1", "eta^2 published in Sec. V.A"),
        **e_y,
        **mu,
        "omega_ratio": Var(b, "1", "Omega_t/Omega_n at the fitted eta^2, rigid massive surface (as Sec. V.A)"),
        "omega_ratio_bat": Var(b, "1", "Omega_t/Omega_n at the fitted eta^2 in the bat frame (mean r_x, r_y)"),
        "r_x_mean": Var(b, "1", "mean r_x of the ball's impacts (model curves)"),
        "r_y_mean": Var(b, "1", "mean r_y of the ball's impacts (model curves)"),
        "psi_stick_boundary": Var(b, "rad", "psi where initial stick ends (solver)"),
        "psi_gross_slip_boundary": Var(b, "rad", "psi where gross slip begins (solver)"),
        "psi_stick_paper": Var(b, "rad", "atan(mu eta^2): end of initial stick as the paper states"),
        "psi_gross_slip_paper": Var(b, "rad", "atan(3.5 mu (1 + e_y)): onset of gross slip as the paper states"),
        "t_stick_end": Var(b, "1", "end of initial stick at psi_history, in units of t_c"),
        "t_separation": Var(b, "1", "separation at psi_history, in units of t_c"),
        "t_stretch_max": Var(b, "1", "time of largest spring stretch at psi_history, in units of t_c"),
        "regime_history": Var(b, "1", "phase sequence at psi_history (code)", flag_attrs(Regime)),
        "n_phases_history": Var(b, "1", "number of stick and slip phases at psi_history"),
        "vtf_x_model": Var(bg, "1", "tan psi / (1 + mean r_x) (Fig. 9 abscissa)"),
        "vtf_y_model": Var(bg, "1", "(1 + e_x) tan psi / (1 + mean r_x), fitted eta^2"),
        "e_x_model": Var(bg, "1", "e_x of the model at the fitted eta^2"),
        "vtf_y_published": Var(bg, "1", f"(1 + e_x) tan psi / (1 + mean r_x), {paper}"),
        "e_x_published": Var(bg, "1", f"e_x of the model at the {paper}"),
        **{k: Var(bs, "1", f"{what} at psi_history") for k, what in HISTORY_VARIABLES.items()},
        "data_ball": Var(fi, None, "ball of each fitted impact"),
        "data_vtf_x": Var(fi, "1", "tan psi / (1 + r_x) of each fitted impact"),
        "data_vtf_y": Var(fi, "1", "(v_ball,t + r omega)/v_bat,n of each fitted impact"),
        "data_vtf_y_err": Var(fi, "1", "effective standard uncertainty of data_vtf_y (NaN: none given)"),
    }


#: The coordinates of ``stronge.nc``. The history samples are not called ``time``: CF tools
#: take a ``time`` coordinate for calendar time; the time in units of t_c is ``t_over_tc``.
STRONGE_COORDS = {
    "ball": Var(("ball",), None, "ball type"),
    "psi_grid": Var(("psi_grid",), "rad", "incidence angle psi of the model curves"),
    "sample": Var(("sample",), "1", "sample number of the time histories"),
    "t_over_tc": Var(("sample",), "1", "time / t_c, t_c = (pi/2)/Omega_n"),
    "impact_fit": Var(("impact_fit",), "1", "fitted impact number"),
}


def stronge_dataset(
    rec: xr.Dataset,
    *,
    e_y: float,
    mu: float,
    vary_e_y: bool,
    vary_mu: bool,
    psi_grid_deg: dict,
    psi_history_deg: float,
    n_time: int,
) -> xr.Dataset:
    """Fit eta^2 per ball and build the Figs. 9-10 products (see module docstring).

    Parameters
    ----------
    rec : xarray.Dataset
        Reconstructed impacts (``results/{dataset}/reconstruct.nc``).
    e_y, mu : float
        Fixed values, or starting values when ``vary_e_y``/``vary_mu``.
    vary_e_y, vary_mu : bool
        Fit e_y and/or mu along with eta^2.
    psi_grid_deg : dict
        ``{start, stop, num}`` of the psi grid of the model curves, deg.
    psi_history_deg : float
        psi of the time histories (Fig. 10), deg.
    n_time : int
        Points of the time histories.

    The keyword arguments are the config's ``stronge`` section; their defaults live in the
    config schema alone.

    Returns
    -------
    xarray.Dataset
        The variables of :func:`stronge_variables` on the coordinates ``STRONGE_COORDS``,
        one row per ball with at least ``MIN_FIT_IMPACTS`` usable impacts; balls with fewer
        are named in the attribute ``balls_not_fitted``.

    Raises
    ------
    ValueError
        No ball has ``MIN_FIT_IMPACTS`` usable impacts.
    """
    usable = rec["flag"].values == 0
    ball_ids = rec["ball"].values.astype(str)
    # A ball needs at least MIN_FIT_IMPACTS usable impacts for a fit (as the e_x fits do).
    counts = {b: int(np.sum(usable & (ball_ids == b))) for b in set(ball_ids)}
    balls = sorted(b for b, n in counts.items() if n >= MIN_FIT_IMPACTS)
    skipped = {b: n for b, n in counts.items() if n < MIN_FIT_IMPACTS}
    if not balls:
        raise ValueError(f"fit_stronge: no ball has {MIN_FIT_IMPACTS} usable impacts (usable per ball: {counts})")
    psi_grid = np.deg2rad(np.linspace(psi_grid_deg["start"], psi_grid_deg["stop"], int(psi_grid_deg["num"])))
    res = [
        analyse_ball(
            vtf_data(rec, usable & (ball_ids == ball)),
            PUBLISHED_ETA2.get(ball),
            psi_grid,
            e_y=e_y,
            mu=mu,
            vary_e_y=vary_e_y,
            vary_mu=vary_mu,
        )
        for ball in balls
    ]
    # Fig. 10: time histories at psi_history for the fitted parameters, on one time grid that
    # reaches the last separation (the balls' e_y differ when e_y is fitted).
    t_max = max(1.0 + r.fit.e_y for r in res)
    hist = [time_history(np.deg2rad(psi_history_deg), r.params, n_time=n_time, t_max=t_max) for r in res]
    nan_curve = ModelCurves(*(np.full(psi_grid.size, np.nan),) * 3)
    curves_pub = [nan_curve if r.published is None else r.published for r in res]
    values = {
        **{k: _column(res, f"fit.{k}") for k in ("eta2", "eta2_err", "eta2_ci_low", "eta2_ci_high")},
        "eta2_n": _column(res, "fit.n").astype(np.int64),
        "eta2_redchi": _column(res, "fit.redchi"),
        "eta2_dof": _column(res, "fit.dof"),
        "eta2_published": _column(res, "eta2_published"),
        **{k: _column(res, f"fit.{k}") for k in ("e_y", "e_y_err", "mu", "mu_err")},
        **{k: _column(res, k) for k in ("omega_ratio", "omega_ratio_bat", "r_x_mean", "r_y_mean")},
        "psi_stick_boundary": _column(res, "boundaries.psi_stick"),
        "psi_gross_slip_boundary": _column(res, "boundaries.psi_gross_slip"),
        "psi_stick_paper": _column(res, "boundaries.psi_stick_paper"),
        "psi_gross_slip_paper": _column(res, "boundaries.psi_gross_slip_paper"),
        **{k: _column(hist, k) for k in ("t_stick_end", "t_separation", "t_stretch_max")},
        "regime_history": _column(hist, "regime").astype(np.int8),
        "n_phases_history": _column(hist, "n_phases").astype(np.int64),
        "vtf_x_model": _column(res, "model.vtf_x"),
        "vtf_y_model": _column(res, "model.vtf_y"),
        "e_x_model": _column(res, "model.e_x"),
        "vtf_y_published": _column(curves_pub, "vtf_y"),
        "e_x_published": _column(curves_pub, "e_x"),
        **{k: _column(hist, k) for k in HISTORY_VARIABLES},
        "data_ball": np.array([b for b, r in zip(balls, res, strict=True) for _ in r.data.x], dtype=str),
        "data_vtf_x": np.concatenate([r.data.x for r in res]),
        "data_vtf_y": np.concatenate([r.data.y for r in res]),
        "data_vtf_y_err": np.concatenate(
            [r.data.sigma if r.data.sigma is not None else np.full(r.data.x.size, np.nan) for r in res]
        ),
    }
    t = hist[0].t
    coords = {
        "ball": np.array(balls, dtype=str),
        "psi_grid": psi_grid,
        "sample": np.arange(t.size, dtype=np.int64),
        "t_over_tc": t,
        "impact_fit": np.arange(values["data_ball"].size, dtype=np.int64),
    }
    attrs = {
        "psi_history_deg": float(psi_history_deg),
        "frame": "bat (recoil factors r_x, r_y)",
        **carried_warnings(rec),
    }
    if skipped:
        attrs["balls_not_fitted"] = "; ".join(
            f"{b}: {n} usable impacts (< {MIN_FIT_IMPACTS})" for b, n in sorted(skipped.items())
        )
    from ..systematics import stronge_systematics

    ds = build_dataset(
        stronge_variables(vary_e_y, vary_mu),
        values,
        coords={k: (var, coords[k]) for k, var in STRONGE_COORDS.items()},
        attrs=attrs,
    )
    return stronge_systematics(ds, rec, e_y=e_y, mu=mu, vary_e_y=vary_e_y, vary_mu=vary_mu)
