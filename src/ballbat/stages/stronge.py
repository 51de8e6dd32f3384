"""Stage fit_stronge: ``results/{dataset}/stronge.nc``, Stronge's contact model fitted per ball (Sec. V.A).

:func:`stronge_variables` and :data:`STRONGE_COORDS` declare the file once; :func:`run` fits eta^2 per
ball and computes the Figs. 9-10 products with the compute functions of :mod:`ballbat.stronge.analysis`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from operator import attrgetter
from typing import TYPE_CHECKING

import numpy as np

from ..linefit import MIN_FIT_IMPACTS
from ..pipeline.config import SectionSettings
from ..pipeline.products import Var, build_dataset, carried_warnings, estimate_vars, flag_attrs
from ..published import STRONGE_E_Y, STRONGE_MU
from ..stronge.analysis import (
    HISTORY_VARIABLES,
    PUBLISHED_ETA2,
    ModelCurves,
    analyse_ball,
    fit_ball,
    time_history,
    vtf_data,
)
from ..stronge.regimes import Regime
from ..systematics import SIDES, SOURCES, has_shifts, shifted_impacts, source_names
from .systematics import systematic_vars

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    import xarray as xr
    from numpy.typing import NDArray


@dataclass(frozen=True)
class StrongeSettings(SectionSettings):
    """Settings of the fit_stronge stage: the config's ``stronge`` section.

    Attributes
    ----------
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
    """

    SECTION = "stronge"

    e_y: float
    mu: float
    vary_e_y: bool
    vary_mu: bool
    psi_grid_deg: dict
    psi_history_deg: float
    n_time: int

    @classmethod
    def from_params(cls, s: Mapping) -> StrongeSettings:
        """Return the workflow's settings from the rule's params (the config's ``stronge`` section)."""
        return cls(
            e_y=s["e_y"],
            mu=s["mu"],
            vary_e_y=s["vary_e_y"],
            vary_mu=s["vary_mu"],
            psi_grid_deg=s["psi_grid_deg"],
            psi_history_deg=s["psi_history_deg"],
            n_time=s["n_time"],
        )


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


def run(settings: StrongeSettings, impacts: xr.Dataset) -> xr.Dataset:
    """Fit eta^2 per ball and build the Figs. 9-10 products (see module docstring).

    Parameters
    ----------
    settings : StrongeSettings
    impacts : xarray.Dataset
        Reconstructed impacts (``results/{dataset}/reconstruct.nc``).

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
    rec = impacts
    balls, skipped, psi_grid, res = _fit_balls(settings, rec)
    # Fig. 10: time histories at psi_history for the fitted parameters, on one time grid that
    # reaches the last separation (the balls' e_y differ when e_y is fitted).
    t_max = max(1.0 + r.fit.e_y for r in res)
    hist = [
        time_history(np.deg2rad(settings.psi_history_deg), r.params, n_time=settings.n_time, t_max=t_max) for r in res
    ]
    values = _stronge_values(balls, psi_grid, res, hist)
    t = hist[0].t
    coords = {
        "ball": np.array(balls, dtype=str),
        "psi_grid": psi_grid,
        "sample": np.arange(t.size, dtype=np.int64),
        "t_over_tc": t,
        "impact_fit": np.arange(values["data_ball"].size, dtype=np.int64),
    }
    attrs = {
        "psi_history_deg": float(settings.psi_history_deg),
        "frame": "bat (recoil factors r_x, r_y)",
        **carried_warnings(rec),
    }
    if skipped:
        attrs["balls_not_fitted"] = "; ".join(
            f"{b}: {n} usable impacts (< {MIN_FIT_IMPACTS})" for b, n in sorted(skipped.items())
        )
    ds = build_dataset(
        stronge_variables(settings.vary_e_y, settings.vary_mu),
        values,
        coords={k: (var, coords[k]) for k, var in STRONGE_COORDS.items()},
        attrs=attrs,
    )
    return stronge_systematics(
        ds, rec, e_y=settings.e_y, mu=settings.mu, vary_e_y=settings.vary_e_y, vary_mu=settings.vary_mu
    )


def _fit_balls(settings: StrongeSettings, rec: xr.Dataset) -> tuple[list[str], dict[str, int], np.ndarray, list]:
    """Fit each ball with at least ``MIN_FIT_IMPACTS`` usable impacts: (balls, the others' counts, psi grid, fits)."""
    e_y, mu, vary_e_y, vary_mu = settings.e_y, settings.mu, settings.vary_e_y, settings.vary_mu
    psi_grid_deg = settings.psi_grid_deg
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
    return balls, skipped, psi_grid, res


def _stronge_values(balls: list[str], psi_grid: np.ndarray, res: list, hist: list) -> dict[str, np.ndarray]:
    """Return the values of stronge.nc's variables from the fits and the time histories."""
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
    return values


# ---------------------------------------------------------------------------------------
# the calibration systematics of eta^2 (ballbat.systematics)


def stronge_systematics(
    ds: xr.Dataset, rec: xr.Dataset, *, e_y: float, mu: float, vary_e_y: bool, vary_mu: bool
) -> xr.Dataset:
    """stronge.nc's dataset with the systematics of eta^2 (and of e_y and mu when fitted).

    Each ball of ``ds`` is fitted again (:func:`ballbat.stronge.analysis.fit_ball`, no interval)
    on its usable impacts at +-1 sigma of each source. ``ds`` is returned unchanged when
    ``rec`` carries no shifts (no camera tracks).
    """
    if not has_shifts(rec):
        return ds
    names = ["eta2"] + (["e_y"] if vary_e_y else []) + (["mu"] if vary_mu else [])
    kw = {"e_y": e_y, "mu": mu, "vary_e_y": vary_e_y, "vary_mu": vary_mu}
    out = stronge_by_source(rec, ds["ball"].values.astype(str), names, starts=ds["eta2"].values, **kw)
    for q in names:  # no value, no systematic
        out[q][:, ~np.isfinite(ds[q].values)] = np.nan
    rel = rec["systematic_rel_sigma"].values
    what = "the tracks reduced again, then normalize, reconstruct and the eta^2 fit"
    if source_names(rec) != list(SOURCES):
        what = "that source's shift of the measured values or properties, then normalize, reconstruct and the eta^2 fit"
    return systematic_vars(ds, out, what, rel, rec["systematic"])


def stronge_by_source(
    rec: xr.Dataset,
    balls: Sequence[str],
    names: Sequence[str],
    *,
    e_y: float,
    mu: float,
    vary_e_y: bool,
    vary_mu: bool,
    starts: Sequence[float] | None = None,
) -> dict[str, np.ndarray]:
    """Systematic of eta^2 (and e_y, mu when fitted: ``names``) of each ball, per source (source x ball).

    The size of :func:`stronge_shifts`' signed changes.
    """
    kw = {"e_y": e_y, "mu": mu, "vary_e_y": vary_e_y, "vary_mu": vary_mu}
    return {q: np.abs(v) for q, v in stronge_shifts(rec, balls, names, starts=starts, **kw).items()}


def stronge_shifts(
    rec: xr.Dataset,
    balls: Sequence[str],
    names: Sequence[str],
    *,
    e_y: float,
    mu: float,
    vary_e_y: bool,
    vary_mu: bool,
    starts: Sequence[float] | None = None,
) -> dict[str, np.ndarray]:
    """Half of (the fit at +1 sigma) - (the fit at -1 sigma) of each source and ball (source x ball).

    Each ball is fitted again (:func:`ballbat.stronge.analysis.fit_ball`, no interval) on its
    usable impacts at +1 and at -1 sigma of each source (:func:`shifted_impacts`); 0 for a
    source without uncertainty. ``rec`` carries the shifts (:func:`has_shifts`). ``starts``: each
    ball's nominal eta^2, where each refit's least squares starts (:func:`ballbat.stronge.fit.fit_eta2`'s
    ``start``; None or NaN: the scan's start). A calibration moves the minimum a little: the refits
    start next to it, without the scan (two thirds of a fit's cost), and stay in the nominal fit's
    basin (issue 39).
    """
    rel = rec["systematic_rel_sigma"].values
    out = {q: np.zeros((rec.sizes["systematic"], len(balls))) for q in names}
    usable = rec["flag"].values == 0
    ball_of = rec["ball"].values.astype(str)
    kw = {"e_y": e_y, "mu": mu, "vary_e_y": vary_e_y, "vary_mu": vary_mu, "interval": False}
    for i in range(rec.sizes["systematic"]):
        if rel[i] == 0:
            continue
        fits = []
        for j in range(len(SIDES)):
            sh = shifted_impacts(rec, i, j)
            fits.append(
                [
                    fit_ball(vtf_data(sh, usable & (ball_of == b)), start=None if starts is None else starts[k], **kw)
                    for k, b in enumerate(balls)
                ]
            )
        for q in names:
            plus, minus = (np.array([getattr(f, q) for f in side]) for side in fits)
            out[q][i] = 0.5 * (plus - minus)
    return out
