"""Stronge's contact model applied to a dataset (Sec. V.A): the eta^2 fit and Figs. 9-10.

For each ball the Eq. vtf data of the usable impacts (``flag == 0``) are fitted with
Stronge's lumped-parameter model in the bat frame, each impact with its own recoil
factors (:func:`ballbat.stronge.fit.fit_eta2`). The result holds the fitted parameters and
intervals, the model curves on a psi grid (Fig. 9a and its extrapolation, Fig. 9b) for the
fitted and for the published eta^2, the time histories at psi_history (Fig. 10) and the
regime boundaries in psi.

The compute functions (:func:`vtf_data`, :func:`model_curves`, :func:`boundaries`,
:func:`time_history`, :func:`analyse_ball`) return arrays and small dataclasses; the stage
:mod:`ballbat.stages.stronge` declares the file ``results/{dataset}/stronge.nc`` once and
fills it.

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017), Sec. V.A.
.. [2] W. J. Stronge, Impact Mechanics (Cambridge University Press, 2000).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from ..designs import Measured, measured_sigma, vtf_design
from ..linefit import effective_sigma, strata_blocks, wls_slope
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
    "VtfNoise",
    "analyse_ball",
    "boundaries",
    "fit_ball",
    "model_curves",
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
    noise: VtfNoise | None = None


@dataclass(frozen=True)
class VtfNoise:
    """How each impact's measurement noise enters the Eq. vtf data (the errors-in-variables correction).

    ``jx``, ``jy``: derivatives of x and y with respect to the measured (v_bat, v_ball, theta,
    omega), each (n, 4) (:func:`ballbat.designs.vtf_design`; psi's are jx cos^2(psi) (1 + r_x),
    as x = tan psi / (1 + r_x)); ``sigma``: their standard uncertainties (n, 4).
    """

    jx: NDArray[np.float64]
    jy: NDArray[np.float64]
    sigma: NDArray[np.float64]


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
    v = rec.variables  # the variables themselves: no DataArray is built per read (xarray's costs ~0.1 ms)
    r, r_x, r_y, alpha = (v[k].values[sel] for k in ("r", "r_x", "r_y", "alpha"))
    x, y, jx, jy = vtf_design(Measured.from_dataset(v, sel), r, r_x, alpha)
    sig = measured_sigma(v, sel)
    sigma = None if sig is None else effective_sigma(jx, jy, sig, wls_slope(x, y)[0])
    noise = None if sig is None else VtfNoise(jx, jy, sig)
    bat = v["bat"].values[sel].astype(str)
    return VtfData(v["psi"].values[sel], x, y, sigma, r_x, r_y, alpha, bat, noise)


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
    errors: bool = True,
    errors_in_variables: bool = True,
    finite_sample: bool = True,
    start: float | None = None,
) -> Eta2Fit:
    """Fit eta^2 to one ball's Eq. vtf data as the workflow does (the workflow and the replicate studies).

    The standard error is the sandwich centred within bats, with Bell-McCaffrey degrees of
    freedom (:func:`ballbat.stronge.fit.fit_eta2` with ``robust=True``, ``strata`` the bats):
    a lab chooses its bats and the impacts per bat, so the misfit of one eta^2 to a bat's own
    e_x is the same in every repetition of the experiment; only the scatter within a bat is.
    The fitted parameters are then corrected for the noise of the measured values, which
    enter the abscissa x and psi as well as y (:func:`eiv_step`), and, with eta^2 the only
    free parameter, for the estimator's bias of order 1/n (:func:`finite_sample_bias`).

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
    errors : compute the standard error and its degrees of freedom (False: NaN, with
        ``interval=False``; the truth of a study needs the value only).
    errors_in_variables : correct for the measurement noise (needs ``data.noise``; off for
        noise-free values, such as a study's truth).
    finite_sample : remove the estimator's bias of order 1/n (:func:`finite_sample_bias`;
        with e_y or mu free as well it is not made). Off for a study's truth, the estimator's
        limit on the design's population.
    start : the least-squares fit's starting eta^2 (:func:`ballbat.stronge.fit.fit_eta2`'s;
        None: its scan).

    Returns
    -------
    Eta2Fit
    """
    d = data
    w = d.sigma if sigma is None else sigma
    fit = fit_eta2(
        d.psi,
        d.x,
        d.y,
        d.r_x,
        d.r_y,
        sigma=w,
        e_y=e_y,
        mu=mu,
        alpha=d.alpha,
        vary_e_y=vary_e_y,
        vary_mu=vary_mu,
        robust=True,
        strata=d.bat,
        interval=interval,
        errors=errors,
        start=start,
    )
    names = ["eta2"] + (["e_y"] if vary_e_y else []) + (["mu"] if vary_mu else [])
    at = {"eta2": fit.eta2, "e_y": fit.e_y, "mu": fit.mu}
    moved = {"eta2": 0.0, "e_y": 0.0, "mu": 0.0}  # fixed parameters do not move
    if errors_in_variables and d.noise is not None and w is not None:
        moved.update(zip(names, eiv_step(d, np.asarray(w, dtype=float), at, names), strict=True))
    if finite_sample and names == ["eta2"]:
        moved["eta2"] -= finite_sample_bias(d, None if w is None else np.asarray(w, dtype=float), at)
    de = moved["eta2"]
    if de == 0.0 and moved["e_y"] == 0.0 and moved["mu"] == 0.0:
        return fit
    return replace(
        fit,
        eta2=fit.eta2 + de,
        eta2_ci_low=fit.eta2_ci_low + de,
        eta2_ci_high=fit.eta2_ci_high + de,
        e_y=fit.e_y + moved["e_y"],
        mu=fit.mu + moved["mu"],
    )


#: Relative step of the central differences in :func:`finite_sample_bias` (of eta^2). The
#: bias moves by less than 2e-4 of itself for steps from 1e-4 to 1e-2 (on a design of 40
#: impacts; a test holds it to 1e-3).
FINITE_SAMPLE_STEP = 1e-3


def finite_sample_bias(data: VtfData, w: NDArray[np.float64] | None, at: dict[str, float]) -> float:
    """Return the bias of order 1/n of the least-squares eta^2 (e_y and mu fixed) at the fit ``at``.

    eta^2 solves S = sum_i g_i = 0 with g_i = r_i r_i', primes the derivatives in eta^2.
    Expanding S about the estimator's limit to second order (Cox and Snell 1968; for
    M-estimators Rilstone, Srivastava and Ullah, J. Econometrics 75, 369 (1996)) gives the bias

        b = E[(S' - A) S] / A^2 - E[S''] Var(S) / (2 A^3),   A = E[S'],

    with g' = r'^2 + r r'' and g'' = 3 r' r'' + r r'''. The impacts are drawn within bats
    whose counts the lab fixes, so the moments are those within bats: centred on each bat's
    mean, with the bats of a single impact pooled, as in the standard error's sandwich
    (:func:`ballbat.linefit.strata_blocks`). They are summed with the divisor n_b, without the
    sandwich's n_b/(n_b - 1), which would change b by a term of order 1/n^2. Plugged in at
    the fit. The bias is positive here: e_x falls ever more slowly as eta^2 grows, so eta^2's
    scatter is skewed high.
    Measured on subsamples of one large noise-free experiment (1 px, 12 impacts per bat), the
    formula predicts the bias the subsamples show (docs/studies.md).
    """
    w = np.ones_like(data.x) if w is None else w

    t0 = at["eta2"]
    h = FINITE_SAMPLE_STEP * t0
    # the five steps in one call of the elementwise model (each row as a call of its own, to round-off)
    eta2 = t0 + np.array([-2.0, -1.0, 0.0, 1.0, 2.0])[:, None] * h
    e = stronge_ex(data.psi, ContactParams(eta2, at["e_y"], at["mu"], data.r_x, data.r_y, data.alpha))
    rm2, rm1, r0, rp1, rp2 = (data.y - (1.0 + e) * data.x) / w
    r1 = (rp1 - rm1) / (2 * h)
    r2 = (rp1 - 2 * r0 + rm1) / h**2
    r3 = (rp2 - 2 * rp1 + 2 * rm1 - rm2) / (2 * h**3)
    g, g1, g2 = r0 * r1, r1**2 + r0 * r2, 3 * r1 * r2 + r0 * r3
    idx, nb, _, c = strata_blocks(r0.size, np.asarray(data.bat).astype(str))

    def centred(v: NDArray[np.float64]) -> NDArray[np.float64]:
        return v - c[idx] * (np.bincount(idx, weights=v, minlength=nb.size) / nb)[idx]

    a = float(np.sum(g1))
    gc = centred(g)
    return float(np.sum(gc * centred(g1)) / a**2 - 0.5 * np.sum(g2) * np.sum(gc**2) / a**3)


#: Relative steps of the central differences in :func:`eiv_step`: psi (rad) and each parameter.
EIV_STEP_PSI = 1e-5
EIV_STEP_PARAM = 1e-4


def eiv_step(data: VtfData, w: NDArray[np.float64], at: dict[str, float], names: list[str]) -> NDArray[np.float64]:
    """Return the corrected-score step of the fitted parameters for the noise of the measured values.

    The least-squares fit solves sum_i r_i dr_i/dp = 0, r_i = (y_i - (1 + e_x(psi_i)) x_i) / w_i.
    With x, y and psi all computed from the same noisy measurements, E[r_i dr_i/dp] at the
    true parameters is not 0 but the covariance of r_i and dr_i/dp, sum_k (dr_i/dm_k)
    (d^2 r_i/dp dm_k) sigma_ik^2 over the measured m = (v_bat, v_ball, theta, omega)
    (independent errors, as in every design of :mod:`ballbat.designs`). Subtracting it gives
    the corrected score (Nakamura 1990; the moment correction of the lines, Fuller 1987, is
    its linear case); one Gauss-Newton step from the fit solves it:
    dp = (J'J)^-1 sum_i c_i. Derivatives of e_x by central differences.
    """
    psi, x = data.psi, data.x
    nz = data.noise
    hp = EIV_STEP_PSI
    steps = {k: EIV_STEP_PARAM * max(abs(at[k]), 1e-3) for k in names}
    ex = _ex_at(data, at, steps, hp)
    dpsi = nz.jx * (np.cos(psi) ** 2 * (1.0 + data.r_x))[:, None]  # x = tan psi / (1 + r_x)
    e_psi = (ex[hp, None, 0] - ex[-hp, None, 0]) / (2 * hp)
    dr = (nz.jy - (1 + ex[0.0, None, 0])[:, None] * nz.jx - (e_psi * x)[:, None] * dpsi) / w[:, None]
    J, c = [], []
    for k, h in steps.items():
        e_k = (ex[0.0, k, 1] - ex[0.0, k, -1]) / (2 * h)
        e_k_psi = (ex[hp, k, 1] - ex[-hp, k, 1] - ex[hp, k, -1] + ex[-hp, k, -1]) / (4 * hp * h)
        dr_k = -((e_k_psi * x)[:, None] * dpsi + e_k[:, None] * nz.jx) / w[:, None]
        J.append(-e_k * x / w)
        c.append(np.sum(dr * dr_k * nz.sigma**2))
    J = np.stack(J, axis=1)
    return np.linalg.solve(J.T @ J, np.asarray(c))


def _ex_at(
    data: VtfData, at: dict[str, float], steps: dict[str, float], hp: float
) -> dict[tuple[float, str | None, int], NDArray[np.float64]]:
    """e_x of the impacts at the points :func:`eiv_step` differentiates, from one call of the model.

    Keys ``(dpsi, name, sign)``: psi shifted by ``dpsi`` (0 or +-``hp``) and parameter ``name``
    by ``sign`` times its step (``(dpsi, None, 0)``: no parameter shifted). The model is
    elementwise, so each row equals a call at that point alone (to round-off: the Newton
    iterations of :func:`stronge_ex` stop when the whole batch has converged).
    """
    keys = [(hp, None, 0), (-hp, None, 0), (0.0, None, 0)]
    for k in steps:
        keys += [(0.0, k, 1), (0.0, k, -1), (hp, k, 1), (-hp, k, 1), (hp, k, -1), (-hp, k, -1)]
    dpsi = np.array([d for d, _, _ in keys])[:, None]
    shift = {q: np.array([s * steps[k] if k == q else 0.0 for _, k, s in keys])[:, None] for q in ("eta2", "e_y", "mu")}
    p = {q: at[q] + shift[q] for q in ("eta2", "e_y", "mu")}
    ex = stronge_ex(data.psi + dpsi, ContactParams(p["eta2"], p["e_y"], p["mu"], data.r_x, data.r_y, data.alpha))
    return dict(zip(keys, ex, strict=True))


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
