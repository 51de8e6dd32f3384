"""Stronge's contact model applied to a dataset (Sec. V.A): the eta^2 fit and Figs. 9-10.

For each ball the Eq. vtf data of the usable impacts (``flag == 0``) are fitted with
Stronge's lumped-parameter model in the bat frame, each impact with its own recoil
factors (:func:`ballbat.stronge.fit.fit_eta2`). The result holds the fitted parameters and
intervals, the model curves on a psi grid (Fig. 9a and its extrapolation, Fig. 9b) for the
fitted and for the published eta^2, the time histories at psi_history_deg (Fig. 10; the paper shows 30 deg) and the
regime boundaries in psi.

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017), Sec. V.A.
.. [2] W. J. Stronge, Impact Mechanics (Cambridge University Press, 2000).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..designs import MEASURED, vtf_design
from ..linefit import MIN_FIT_IMPACTS, effective_sigma, wls_slope
from ..pipeline.products import Var, build_dataset, flag_attrs
from ..published import STRONGE_E_Y as PUBLISHED_E_Y
from ..published import STRONGE_MU as PUBLISHED_MU
from ..published import per_ball
from .fit import fit_eta2
from .model import Regime, omega_ratio, regime_code, stronge_ex, stronge_solve
from .regimes import regime_boundaries

#: eta^2 published in Sec. V.A (with e_y = mu = 0.5), drawn beside the fits.
PUBLISHED_ETA2 = per_ball("eta2")


def _fit_inputs(rec, sel):
    meas = [np.asarray(rec[k].values[sel], dtype=float) for k in MEASURED]
    r, r_x, alpha = (rec[k].values[sel] for k in ("r", "r_x", "alpha"))
    x, y, jx, jy = vtf_design(*meas, r, r_x, alpha)
    sigma = None
    if all(f"{k}_err" in rec for k in MEASURED):
        sig = np.stack([rec[f"{k}_err"].values[sel] for k in MEASURED], axis=1).astype(float)
        # Effective variance of y - (1 + e_x) x with the local slope of the data (the model's
        # slope varies slowly with psi over the experiment's range).
        sigma = effective_sigma(jx, jy, sig, wls_slope(x, y)[0])
    return x, y, sigma


#: The coordinates of stronge.nc.
STRONGE_COORDS = {
    "ball": Var(("ball",), None, "ball type"),
    "psi_grid": Var(("psi_grid",), "rad", "incidence angle psi of the model curves"),
    "sample": Var(("sample",), "1", "sample of the time histories"),
    "t_over_tc": Var(("sample",), "1", "time / t_c, t_c = (pi/2)/Omega_n"),
    "impact_fit": Var(("impact_fit",), "1", "fitted impact number"),
}


def stronge_table(vary_e_y: bool, vary_mu: bool) -> dict[str, Var]:
    """Return the variables of stronge.nc, declared once (name -> :class:`Var`)."""
    b, g, h, f = ("ball",), ("ball", "psi_grid"), ("ball", "sample"), ("impact_fit",)
    at = "at psi_history"
    table = {
        "eta2": Var(
            b,
            "1",
            "eta^2 = k_n/k_t fitted to Eq. vtf (Sec. V.A)",
            {"ancillary_variables": "eta2_err eta2_ci_low eta2_ci_high eta2_n eta2_redchi"},
        ),
        "eta2_err": Var(b, "1", "standard error of eta^2 (covariance scaled by reduced chi^2)"),
        "eta2_ci_low": Var(b, "1", "lower end of the 95 % profile-likelihood interval of eta^2"),
        "eta2_ci_high": Var(b, "1", "upper end of the 95 % profile-likelihood interval of eta^2"),
        "eta2_published": Var(b, "1", "eta^2 published in Sec. V.A"),
        "eta2_n": Var(b, "1", "number of impacts in the eta^2 fit"),
        "eta2_redchi": Var(b, "1", "reduced chi-square of the eta^2 fit"),
        "e_y": Var(b, "1", "normal COR e_y of the model (fixed unless fitted)", {"vary": int(vary_e_y)}),
        "e_y_err": Var(b, "1", "standard error of e_y (NaN when fixed)"),
        "mu": Var(b, "1", "friction coefficient mu of the model (fixed unless fitted)", {"vary": int(vary_mu)}),
        "mu_err": Var(b, "1", "standard error of mu (NaN when fixed)"),
        "omega_ratio": Var(b, "1", "Omega_t/Omega_n on a rigid surface at the fitted eta^2 (Sec. V.A)"),
        "r_x_mean": Var(b, "1", "mean r_x of the ball's impacts (model curves)"),
        "r_y_mean": Var(b, "1", "mean r_y of the ball's impacts (model curves)"),
        "psi_stick_boundary": Var(b, "rad", "psi where initial stick ends (solver)"),
        "psi_gross_slip_boundary": Var(b, "rad", "psi where gross slip begins (solver)"),
        "psi_stick_paper": Var(b, "rad", "atan(mu eta^2): end of initial stick as the paper states"),
        "psi_gross_slip_paper": Var(b, "rad", "atan(3.5 mu (1 + e_y)): onset of gross slip as the paper states"),
        "t_stick_end": Var(b, "1", f"end of initial stick {at}, in units of t_c"),
        "t_separation": Var(b, "1", f"separation {at}, in units of t_c"),
        "t_stretch_max": Var(b, "1", f"time of largest spring stretch {at}, in units of t_c"),
        "regime_history": Var(b, "1", f"phase sequence {at}", flag_attrs(Regime)),
        "vtf_x_model": Var(g, "1", "tan psi / (1 + mean r_x) (Fig. 9 abscissa)"),
        "vtf_y_model": Var(g, "1", "(1 + e_x) tan psi / (1 + mean r_x), fitted eta^2"),
        "e_x_model": Var(g, "1", "e_x of the model at the fitted eta^2"),
        "vtf_y_published": Var(
            g,
            "1",
            f"(1 + e_x) tan psi / (1 + mean r_x), published eta^2, e_y = {PUBLISHED_E_Y}, mu = {PUBLISHED_MU}",
        ),
        "e_x_published": Var(
            g, "1", f"e_x of the model at the published eta^2, e_y = {PUBLISHED_E_Y}, mu = {PUBLISHED_MU}"
        ),
        "data_ball": Var(f, None, "ball of each fitted impact"),
        "data_vtf_x": Var(f, "1", "tan psi / (1 + r_x) of each fitted impact"),
        "data_vtf_y": Var(f, "1", "(v_ball,t + r omega)/v_bat,n of each fitted impact"),
        "data_vtf_y_err": Var(f, "1", "effective standard uncertainty of data_vtf_y (NaN: none given)"),
    }
    for k, what in (
        ("normal_force", "normal force / peak normal force"),
        ("tangential_force", "tangential spring force / peak normal force"),
        ("tangential_velocity", "tangential velocity of the ball's contact point / initial normal speed"),
        ("spring_stretch", "tangential spring stretch / (v_n / Omega_n)"),
        ("stick", "1 while the contact point sticks, 0 while it slips (NaN after separation)"),
    ):
        table[k] = Var(h, "1", f"{what} {at}")
    return table


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
    rec : reconstructed impacts (``results/{dataset}/reconstruct.nc``).
    e_y, mu : fixed values, or starting values when ``vary_e_y``/``vary_mu``.
    psi_grid_deg : ``{start, stop, num}`` of the psi grid of the model curves, deg.

    The arguments are the config's ``stronge`` section (defaults in the config schema).
    psi_history_deg : psi of the time histories (Fig. 10), deg.
    n_time : points of the time histories.
    """
    usable = rec["flag"].values == 0
    ball_ids = rec["ball"].values.astype(str)
    # A ball needs at least MIN_FIT_IMPACTS usable impacts for a fit (as the e_x fits do).
    counts = {b: int(np.sum(usable & (ball_ids == b))) for b in set(ball_ids)}
    balls = sorted(b for b, n in counts.items() if n >= MIN_FIT_IMPACTS)
    skipped = {b: n for b, n in counts.items() if n < MIN_FIT_IMPACTS}
    psi_grid = np.deg2rad(np.linspace(psi_grid_deg["start"], psi_grid_deg["stop"], int(psi_grid_deg["num"])))
    psi_h = np.deg2rad(psi_history_deg)
    nb, ng = len(balls), psi_grid.size

    scal = {
        k: np.full(nb, np.nan)
        for k in (
            "eta2",
            "eta2_err",
            "eta2_ci_low",
            "eta2_ci_high",
            "e_y",
            "e_y_err",
            "mu",
            "mu_err",
            "redchi",
            "omega_ratio",
            "r_x_mean",
            "r_y_mean",
            "psi_stick_boundary",
            "psi_gross_slip_boundary",
            "psi_stick_paper",
            "psi_gross_slip_paper",
            "t_stick_end",
            "t_separation",
            "t_stretch_max",
            "eta2_published",
        )
    }
    n_fit = np.zeros(nb, dtype=np.int64)
    curves = {
        k: np.full((nb, ng), np.nan)
        for k in ("vtf_x_model", "vtf_y_model", "e_x_model", "vtf_y_published", "e_x_published")
    }
    hist = None
    regimes_h = []
    data_ball, data_x, data_y, data_err = [], [], [], []

    for i, ball in enumerate(balls):
        sel = usable & (ball_ids == ball)
        x, y, sigma = _fit_inputs(rec, sel)
        psi = rec["psi"].values[sel]
        r_x, r_y, alpha = (rec[k].values[sel] for k in ("r_x", "r_y", "alpha"))
        fit = fit_eta2(
            psi, x, y, r_x, r_y, sigma=sigma, e_y=e_y, mu=mu, alpha=alpha, vary_e_y=vary_e_y, vary_mu=vary_mu
        )
        for k in ("eta2", "eta2_err", "eta2_ci_low", "eta2_ci_high", "e_y", "e_y_err", "mu", "mu_err", "redchi"):
            scal[k][i] = getattr(fit, k)
        n_fit[i] = fit.n
        a = float(np.mean(alpha))
        rxm, rym = float(np.mean(r_x)), float(np.mean(r_y))
        scal["r_x_mean"][i], scal["r_y_mean"][i] = rxm, rym
        scal["omega_ratio"][i] = float(omega_ratio(fit.eta2, 0.0, 0.0, a))
        # Model curves on the grid (bat frame, mean recoil factors of the ball's impacts).
        xg = np.tan(psi_grid) / (1.0 + rxm)
        ex = stronge_ex(psi_grid, fit.eta2, fit.e_y, fit.mu, rxm, rym, a)
        curves["vtf_x_model"][i] = xg
        curves["e_x_model"][i] = ex
        curves["vtf_y_model"][i] = (1.0 + ex) * xg
        pub = PUBLISHED_ETA2.get(ball)
        if pub is not None:
            scal["eta2_published"][i] = pub
            exp = stronge_ex(psi_grid, pub, PUBLISHED_E_Y, PUBLISHED_MU, rxm, rym, a)
            curves["e_x_published"][i] = exp
            curves["vtf_y_published"][i] = (1.0 + exp) * xg
        rb = regime_boundaries(fit.eta2, fit.e_y, fit.mu, rxm, rym, a)
        stick = [p for p, b in zip(rb.psi, rb.below, strict=True) if str(b).startswith("stick")]
        gross = [p for p, ab in zip(rb.psi, rb.above, strict=True) if ab == "gross-slip"]
        scal["psi_stick_boundary"][i] = stick[0] if stick else np.nan
        scal["psi_gross_slip_boundary"][i] = gross[0] if gross else np.nan
        scal["psi_stick_paper"][i] = rb.psi_stick_paper
        scal["psi_gross_slip_paper"][i] = rb.psi_gross_paper
        # Fig. 10: time histories at psi_history for the fitted eta^2.
        sol = stronge_solve(psi_h, fit.eta2, fit.e_y, fit.mu, rxm, rym, a, histories=True, n_time=n_time)
        if hist is None:
            hist = {
                k: np.full((nb, sol.t.size), np.nan)
                for k in ("normal_force", "tangential_force", "tangential_velocity", "spring_stretch", "stick")
            }
            t_grid = sol.t
        hist["normal_force"][i] = sol.normal_force
        hist["tangential_force"][i] = sol.tangential_force
        hist["tangential_velocity"][i] = sol.u
        hist["spring_stretch"][i] = sol.stretch
        stuck = np.where(np.isfinite(sol.normal_force), (np.abs(sol.c_velocity) < 1e-12).astype(float), np.nan)
        hist["stick"][i] = stuck
        scal["t_stick_end"][i] = float(sol.t_stick_end)
        scal["t_separation"][i] = float(sol.t_separation)
        scal["t_stretch_max"][i] = float(sol.t_stretch_max)
        regimes_h.append(int(regime_code(str(sol.regime))))
        data_ball += [ball] * x.size
        data_x.append(x)
        data_y.append(y)
        data_err.append(sigma if sigma is not None else np.full(x.size, np.nan))

    if hist is None:
        raise ValueError(f"fit_stronge: no ball has {MIN_FIT_IMPACTS} usable impacts (usable per ball: {counts})")
    table = stronge_table(vary_e_y, vary_mu)
    values = {
        **{k: scal[k] for k in table if k in scal},
        "eta2_n": n_fit,
        "eta2_redchi": scal["redchi"],
        "regime_history": np.array(regimes_h, dtype=np.int8),
        **curves,
        "data_ball": np.array(data_ball, dtype=str),
        "data_vtf_x": np.concatenate(data_x),
        "data_vtf_y": np.concatenate(data_y),
        "data_vtf_y_err": np.concatenate(data_err),
        **hist,
    }
    coord_values = {
        "ball": np.array(balls, dtype=str),
        "psi_grid": psi_grid,
        "sample": np.arange(t_grid.size, dtype=np.int64),
        "t_over_tc": t_grid,
        "impact_fit": np.arange(len(data_ball), dtype=np.int64),
    }
    coords = {k: (STRONGE_COORDS[k], v) for k, v in coord_values.items()}
    ds = build_dataset(table, {k: values[k] for k in table}, coords)
    ds.attrs.update({"psi_history_deg": float(psi_history_deg), "frame": "bat (recoil factors r_x, r_y)"})
    if skipped:
        ds.attrs["balls_not_fitted"] = "; ".join(
            f"{b}: {n} usable impacts (< {MIN_FIT_IMPACTS})" for b, n in sorted(skipped.items())
        )
    return ds
