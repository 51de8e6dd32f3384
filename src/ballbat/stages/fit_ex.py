"""Stage fit_ex: ``results/{dataset}/fit_ex.nc``, the Sec. IV fits of one dataset (:mod:`ballbat.fitting`).

:func:`fit_ex_table` declares the file once; :func:`run` fits (:func:`ballbat.fitting.analyze_impacts`),
refuses an e_x no collision can have (:func:`ballbat.fitting.check_physical`) and assembles the file
(:func:`results_dataset`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..fitting import (
    CONTACT_QUANTITIES,
    FitGrid,
    FitStatus,
    Sec4,
    analyze_impacts,
    check_physical,
    fit_status,
    with_contact_error,
)
from ..pipeline.config import SectionSettings
from ..pipeline.products import Var, build_dataset, carried_warnings, estimate_vars, flag_attrs
from ..systematics import FIT_QUANTITIES, SIDES, SOURCES, FitSystematics, has_shifts, shifted_impacts, source_names
from .systematics import systematic_vars

if TYPE_CHECKING:
    from collections.abc import Mapping


@dataclass(frozen=True)
class FitExSettings(SectionSettings):
    """Settings of the fit_ex stage.

    Attributes
    ----------
    mu_k_example : float
        Friction of the Sec. IV gross-slip example (config ``analysis.mu_k_example``).
    systematic : bool
        Fit the pixel-scale systematic of e_x (:func:`ballbat.fitting.scale_systematic`; a
        replicate of a study fits it where it draws its calibration or its properties,
        :func:`ballbat.studies.replicates.run_replicate`, and skips it elsewhere).
    check_physical : bool
        Refuse a fitted e_x outside [-1, 1] (:class:`ballbat.fitting.ImplausibleFit`); the
        replicate studies record every replicate's numbers as they come.
    mu_k_bound : bool
        Estimate the lower bound on mu_k (Eq. muk, corrected for picking the largest value:
        :func:`ballbat.fitting.largest_value`, about 1.3 s a ball at 35 000 impacts). Always, but
        in a study's truth job, which reads only its truth (the largest noise-free value).
    """

    SECTION = "analysis"

    mu_k_example: float
    systematic: bool
    check_physical: bool
    mu_k_bound: bool

    @classmethod
    def from_params(cls, params: Mapping) -> FitExSettings:
        """Return the workflow's settings from the rule's params (``mu_k_example``, as config ``analysis``)."""
        return cls(mu_k_example=float(params["mu_k_example"]), systematic=True, check_physical=True, mu_k_bound=True)


# ---------------------------------------------------------------------------------------
# fit_ex.nc: the declared table and its assembly

#: The line-fit families of fit_ex.nc: name -> (dims, units, what).
FIT_FAMILIES = {
    "e_x": (("ball", "bat"), "1", "tangential coefficient of restitution e_x per bat and ball (Eq. omega)"),
    "e_x_pooled": (("ball",), "1", "tangential coefficient of restitution e_x pooled over bats (Eq. ex, Fig. 5)"),
    "tan_ratio_slope": (("ball",), "1", "slope of tan(psi - theta) against tan psi (Eq. ratio, Fig. 6)"),
    "spin_theta_slope": (("ball",), "rad s-1 rad-1", "slope of normalised spin against theta (Fig. 3)"),
    "speed_theta_slope": (("ball",), "m s-1 rad-1", "slope of normalised exit speed against theta (Fig. 4)"),
}

#: Families whose fitted slope is 1 + e_x (Eq. omega): the file holds e_x = slope - 1.
_SLOPE_IS_ONE_PLUS = ("e_x", "e_x_pooled")


def fit_ex_table(
    has_truth: bool, mu_k_example: float, has_scale: bool = False, has_contact: bool = False
) -> dict[str, Var]:
    """Return the variables of fit_ex.nc, declared once (name -> :class:`Var`).

    ``has_scale``: the dataset carries a pixel-scale uncertainty (reduced from camera
    tracks), so e_x gets a systematic error (``*_err_scale``). ``has_contact``: its impacts carry
    the contact population's shifts, so the pooled quantities get ``*_err_contact``
    (:func:`contact_error_vars`).
    """
    table: dict[str, Var] = {}
    for name, (dims, units, what) in FIT_FAMILIES.items():
        table.update(estimate_vars(name, dims, units, what))
        if has_scale and name in _SLOPE_IS_ONE_PLUS:
            table[f"{name}_err_scale"] = Var(
                dims,
                units,
                f"systematic error of {name} from the pixel-scale uncertainty of the swing camera "
                "(shared by every impact; not included in the standard error)",
            )
        if has_truth:
            table[f"truth_{name}"] = Var(
                dims, units, f"true {what} (same estimator on the noise-free truth)", {"ballbat_role": "truth"}
            )
    for name in ("spin_theta_slope", "speed_theta_slope"):
        units = FIT_FAMILIES[name][1].replace(" rad-1", "")
        table[f"{name}_intercept"] = Var(("ball",), units, f"intercept at theta = 0 of the fit of {name}")
    for name in _SLOPE_IS_ONE_PLUS:
        dims = FIT_FAMILIES[name][0]
        table[f"{name}_status"] = Var(
            dims, "1", f"why {name} has no value (0: it has one; the count is {name}_n)", flag_attrs(FitStatus)
        )
    table.update({**scatter_vars(), **(contact_error_vars() if has_contact else {})})
    table["e_y_implied"] = Var(
        ("ball",),
        "1",
        "normal COR e_y implied by the Eq. ratio slope (each impact's r_x, r_y and its bat's e_x)",
        {"ancillary_variables": "e_y_implied_err"},
    )
    table["e_y_implied_err"] = Var(
        ("ball",),
        "1",
        "standard error of e_y implied (leverage-corrected HC2 sandwich: the impacts' influences via the slope "
        "and e_x)",
    )
    table["mu_k_lower_bound"] = Var(
        ("ball",),
        "1",
        "lower bound on mu_k: largest tan(psi - theta) (Eq. muk)",
        {"ancillary_variables": "mu_k_lower_bound_err mu_k_lower_bound_impact"},
    )
    table["mu_k_lower_bound_err"] = Var(
        ("ball",),
        "1",
        "measurement uncertainty of that largest tan(psi - theta) (not the spread of a sample maximum: "
        "it says how well the largest value of these impacts is measured)",
    )
    table["mu_k_lower_bound_impact"] = Var(("ball",), "1", "impact number of the largest tan(psi - theta)")
    for nm, units, what in (
        ("psi", "rad", "impact angle psi"),
        ("theta", "rad", "angle theta"),
        ("omega", "rad s-1", "spin at the reference bat speed"),
    ):
        table[f"gross_slip_{nm}"] = Var(
            ("ball",), units, f"{what} where gross slip sets in for mu_k = {mu_k_example} (Sec. IV)"
        )
    if has_truth:
        for q in ("e_y_implied", "mu_k_lower_bound"):
            table[f"truth_{q}"] = Var(("ball",), "1", f"true {q.replace('_', ' ')}", {"ballbat_role": "truth"})
    return table


#: The fits with an intrinsic-scatter term (``linefit.eiv_line``): name -> (dims, what scatters).
SCATTER_FITS = {
    "e_x": (("ball", "bat"), "e_x from impact to impact (per bat and ball)"),
    "e_x_pooled": (("ball",), "e_x from impact to impact within a bat (pooled over the ball's bats)"),
    "tan_ratio_slope": (("ball",), "the Eq. ratio slope from impact to impact within a bat (pooled over bats)"),
}


def scatter_vars() -> dict[str, Var]:
    """Declare each fit's intrinsic scatter and its 95 % interval (``linefit.eiv_line``; :data:`SCATTER_FITS`)."""
    table = {}
    for name, (dims, what) in SCATTER_FITS.items():
        table[f"{name}_scatter"] = Var(
            dims,
            "1",
            f"intrinsic standard deviation tau of {what}, fitted with the slope (Paule-Mandel; 0: the "
            "measurement errors explain the scatter)",
            {"ancillary_variables": f"{name}_scatter_ci_low {name}_scatter_ci_high"},
        )
        for side, bound in (("low", "lower"), ("high", "upper")):
            table[f"{name}_scatter_ci_{side}"] = Var(
                dims, "1", f"{bound} bound of the 95 % interval of {name}_scatter (Q-profile)"
            )
    return table


def contact_error_vars() -> dict[str, Var]:
    """Declare each pooled quantity's error from the contact population's estimate (``<q>_err_contact``)."""
    dims = {"e_x": ("ball", "bat"), "e_y_implied": ("ball",)}
    return {
        f"{q}_err_contact": Var(
            dims.get(q, ("ball",)),
            "1",
            f"part of {q}_err from the estimate of the ball type's contact-time population (statistical, shared by "
            f"its impacts; already in {q}_err in quadrature): half the change of {q} when the tracks are reduced with "
            "the population's mean contact time at +1 and -1 standard error",
        )
        for q in CONTACT_QUANTITIES
    }


def results_dataset(res: Sec4) -> xr.Dataset:
    """fit_ex.nc's contents: the :class:`Sec4` results on the declared table (dims ball, bat)."""
    table = fit_ex_table(res.has_truth, res.mu_k_example, res.systematic is not None, res.contact_error is not None)
    coords = {
        "ball": (Var(("ball",), None, "ball type"), np.array(res.balls, dtype=str)),
        "bat": (Var(("bat",), None, "bat"), np.array(res.bats, dtype=str)),
    }
    ds = build_dataset(
        table,
        results_values(res),
        coords,
        {"mu_k_example": res.mu_k_example},
    )
    return add_fit_systematics(ds, res.systematics)


def results_values(res: Sec4) -> dict[str, np.ndarray]:
    """fit_ex.nc's variables of :func:`results_dataset` by name, as arrays (no Dataset: the refits read these)."""
    values: dict[str, np.ndarray] = {}
    for name in FIT_FAMILIES:
        grid: FitGrid = getattr(res, name)
        shift = -1.0 if name in _SLOPE_IS_ONE_PLUS else 0.0
        values[name] = grid.field("slope", shift)
        values[f"{name}_err"] = grid.field("slope_err")
        values[f"{name}_ci_low"] = grid.field("slope_ci_low", shift)
        values[f"{name}_ci_high"] = grid.field("slope_ci_high", shift)
        values[f"{name}_n"] = grid.field("n").astype(np.int64)
        values[f"{name}_redchi"] = grid.field("redchi")
        if res.has_truth:
            values[f"truth_{name}"] = grid.truth
    for name in ("spin_theta_slope", "speed_theta_slope"):
        values[f"{name}_intercept"] = getattr(res, name).field("intercept")
    for name in SCATTER_FITS:
        for k in ("scatter", "scatter_ci_low", "scatter_ci_high"):
            values[f"{name}_{k}"] = getattr(res, name).field(k)
    for name in _SLOPE_IS_ONE_PLUS:
        values[f"{name}_status"] = np.vectorize(lambda f: int(fit_status(f)), otypes=[np.int8])(getattr(res, name).fits)
    values.update({k: v for k, v in res.per_ball.items() if res.has_truth or not k.startswith("truth_")})
    if res.systematic is not None:
        values.update(res.systematic)
    if res.contact_error is not None:
        values.update({f"{q}_err_contact": v for q, v in res.contact_error.items()})
    return values


def run(settings: FitExSettings, impacts: xr.Dataset) -> xr.Dataset:
    """Return the Sec. IV fits of a reconstructed dataset (``reconstruct.nc``), as a Dataset ready to write.

    Raises :class:`~ballbat.fitting.ImplausibleFit` when a fitted e_x lies outside [-1, 1]
    (an error for the dataset, not a note: such a number is always a mistake in the data;
    unless ``settings.check_physical`` is false).
    """
    return fit(settings, impacts)[0]


def fit(settings: FitExSettings, impacts: xr.Dataset) -> tuple[xr.Dataset, FitSystematics | None]:
    """:func:`run`'s dataset and the calibration systematics it holds, with their signs (None: none fitted)."""
    res = with_contact_error(
        impacts,
        analyze_impacts(impacts, settings.mu_k_example, systematic=settings.systematic, mu_k_bound=settings.mu_k_bound),
    )
    if settings.systematic and has_shifts(impacts):  # every calibration source, the tracks reduced again
        res.systematics = fit_systematics(impacts, res)
        res.systematic = scale_entries(res.systematics)
    if settings.check_physical:
        check_physical(res)
    ds = results_dataset(res)
    ds.attrs["n_impacts"] = int(impacts.sizes["impact"])
    ds.attrs["n_excluded"] = int((impacts["flag"].values != 0).sum())
    ds.attrs["v_ref"] = float(impacts.attrs["v_ref"])
    ds.attrs.update(carried_warnings(impacts))
    return ds, res.systematics


def not_fitted(ds: xr.Dataset) -> list[str]:
    """List the fits of e_x in fit_ex.nc that have impacts but no value, one line each (for the log)."""
    lines = []
    for name in _SLOPE_IS_ONE_PLUS:
        status, n = ds[f"{name}_status"], ds[f"{name}_n"]
        for idx in zip(*np.nonzero(status.values > FitStatus.NO_IMPACTS), strict=True):
            where = ", ".join(f"{d} {ds[d].values[i]}" for d, i in zip(status.dims, idx, strict=True))
            reason = FitStatus(int(status.values[idx])).name.lower().replace("_", " ")
            lines.append(f"{name} ({where}): not fitted: {reason} ({int(n.values[idx])} usable impacts)")
    return lines


# ---------------------------------------------------------------------------------------
# the calibration systematics of every quantity (ballbat.systematics)


def fit_systematics(rec: xr.Dataset, res: Sec4) -> FitSystematics:
    """Every quantity of fit_ex.nc at +-1 sigma of each source; half the differences.

    Parameters
    ----------
    rec : xarray.Dataset
        Reconstructed impacts carrying the shifts (:func:`has_shifts`).
    res : Sec4
        The nominal fits (labels, mu_k of the example).

    Returns
    -------
    FitSystematics
    """
    nominal = results_values(res)
    rel = rec["systematic_rel_sigma"].values
    names = source_names(rec)
    out = {q: np.zeros((len(names), *np.shape(nominal[q]))) for q in FIT_QUANTITIES}
    for q in FIT_QUANTITIES:  # no value, no systematic
        out[q][:, ~np.isfinite(nominal[q])] = np.nan
    for i in range(len(names)):
        if rel[i] == 0:
            continue
        fits = [
            results_values(
                analyze_impacts(shifted_impacts(rec, i, j), res.mu_k_example, systematic=False, errors=False)
            )
            for j in range(len(SIDES))
        ]
        for q in FIT_QUANTITIES:
            out[q][i] = 0.5 * (fits[0][q] - fits[1][q])
    return FitSystematics({q: np.abs(v) for q, v in out.items()}, rel, out, names, rec["systematic"].attrs["long_name"])


def scale_entries(fs: FitSystematics) -> dict[str, np.ndarray] | None:
    """``e_x_err_scale`` and ``e_x_pooled_err_scale``: the swing camera's pixel-scale systematic of e_x.

    None for a dataset without camera tracks (its sources are an instrument's or properties').
    """
    if fs.names is not None and "swing_m_per_px" not in fs.names:
        return None
    i = (fs.names or list(SOURCES)).index("swing_m_per_px")
    return {"e_x_err_scale": fs.by_source["e_x"][i], "e_x_pooled_err_scale": fs.by_source["e_x_pooled"][i]}


def add_fit_systematics(ds: xr.Dataset, fs: FitSystematics | None) -> xr.Dataset:
    """fit_ex.nc's dataset with the systematics of :func:`fit_systematics` (unchanged for None)."""
    if fs is None:
        return ds
    what = "the tracks reduced again, then normalize, reconstruct and the fit"
    if fs.names is None:
        return systematic_vars(ds, fs.by_source, what, fs.rel_sigma)
    if fs.names != list(SOURCES):
        what = "that source's shift of the measured values or properties, then normalize, reconstruct and the fit"
    coord = xr.DataArray(np.array(fs.names, dtype=str), dims="systematic", attrs={"long_name": fs.long_name})
    return systematic_vars(ds, fs.by_source, what, fs.rel_sigma, coord)
