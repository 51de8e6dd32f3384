"""The calibration systematics in the result files: reduce.nc's shifts, fit_ex.nc's and stronge.nc's systematics.

The computation is :mod:`ballbat.systematics` (the sources, the tracks reduced again, the shifted
impacts); this stage-layer module refits every quantity at +-1 sigma of each source with the
same tables as the stages (:func:`fit_systematics`) and adds the variables to the stages'
Datasets: ``<name>_shift`` (reduce.nc), ``<q>_syst_by_source``, ``<q>_syst`` and
``<q>_err_total`` (fit_ex.nc, stronge.nc).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..systematics import (
    FIT_QUANTITIES,
    SHIFT_UNITS,
    SHIFTED,
    SIDES,
    SOURCES,
    FitSystematics,
    Shifts,
    has_shifts,
    shifted_impacts,
    stronge_by_source,
)

if TYPE_CHECKING:
    import xarray as xr

    from ..fitting import Sec4


def _coords() -> dict[str, tuple]:
    return {
        "systematic": (
            ("systematic",),
            np.array(list(SOURCES), dtype=str),
            {"long_name": "calibration source of a systematic: " + "; ".join(f"{k}: {v}" for k, v in SOURCES.items())},
        ),
    }


def _rel_sigma_var(rel: np.ndarray) -> tuple:
    return (
        ("systematic",),
        np.asarray(rel, dtype=float),
        {"units": "1", "long_name": "relative standard uncertainty of each calibration source (0: none stated)"},
    )


def add_shifts(ds: xr.Dataset, shifts: Shifts | None) -> xr.Dataset:
    """Return reduce.nc's dataset with the shifts of :func:`reduce_shifts` (unchanged for None)."""
    if shifts is None:
        return ds
    out = ds.assign_coords(
        **_coords(),
        shift=(
            ("shift",),
            np.array(SIDES, dtype=np.int8),
            {"units": "1", "long_name": "calibration shifted by this many standard uncertainties"},
        ),
    )
    out["systematic_rel_sigma"] = _rel_sigma_var(shifts.rel_sigma)
    for k in SHIFTED:
        base = k.removesuffix("_err")
        what = f"the standard uncertainty of {base}" if k.endswith("_err") else base
        out[f"{k}_shift"] = (
            ("systematic", "shift", "impact"),
            shifts.shift[k],
            {
                "units": SHIFT_UNITS[base],
                "long_name": f"change of {what} when the tracks are reduced with one calibration shifted "
                "(systematic; 0 where the source has no uncertainty)",
                "ballbat_role": "systematic",
            },
        )
    return out


def _combine(by_source: np.ndarray) -> np.ndarray:
    return np.sqrt(np.sum(by_source**2, axis=0))


def _systematic_vars(ds: xr.Dataset, by_source: dict[str, np.ndarray], what: str, rel: np.ndarray) -> xr.Dataset:
    """``ds`` with ``<q>_syst_by_source``, ``<q>_syst`` and (where ``<q>_err`` is) ``<q>_err_total``."""
    out = ds.assign_coords(**_coords()) if "systematic" not in ds.coords else ds
    out["systematic_rel_sigma"] = _rel_sigma_var(rel)
    for q, per in by_source.items():
        dims, attrs = ds[q].dims, ds[q].attrs
        units = {"units": attrs["units"]} if "units" in attrs else {}
        syst = _combine(per)
        out[f"{q}_syst_by_source"] = (
            ("systematic", *dims),
            per,
            {
                **units,
                "long_name": f"systematic error of {q} from each calibration source: half the change of {q} "
                f"between that calibration at +1 and at -1 standard uncertainty ({what})",
                "ballbat_role": "systematic",
            },
        )
        out[f"{q}_syst"] = (
            dims,
            syst,
            {
                **units,
                "long_name": f"systematic error of {q}: every calibration source in quadrature "
                "(shared by every impact; not in the standard error)",
                "ballbat_role": "systematic",
            },
        )
        if f"{q}_err" in ds:
            out[f"{q}_err_total"] = (
                dims,
                np.hypot(ds[f"{q}_err"].values, syst),
                {**units, "long_name": f"standard error and systematic error of {q} in quadrature"},
            )
    return out


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
    from ..fitting import analyze_impacts
    from .fit_ex import results_dataset  # the same table of quantities as fit_ex.nc

    nominal = results_dataset(res)
    rel = rec["systematic_rel_sigma"].values
    out = {q: np.zeros((len(SOURCES), *nominal[q].shape)) for q in FIT_QUANTITIES}
    for q in FIT_QUANTITIES:  # no value, no systematic
        out[q][:, ~np.isfinite(nominal[q].values)] = np.nan
    for i in range(len(SOURCES)):
        if rel[i] == 0:
            continue
        fits = [
            results_dataset(analyze_impacts(shifted_impacts(rec, i, j), res.mu_k_example, systematic=False))
            for j in range(len(SIDES))
        ]
        for q in FIT_QUANTITIES:
            out[q][i] = 0.5 * np.abs(fits[0][q].values - fits[1][q].values)
    return FitSystematics(out, rel)


def scale_entries(fs: FitSystematics) -> dict[str, np.ndarray]:
    """``e_x_err_scale`` and ``e_x_pooled_err_scale``: the swing camera's pixel-scale systematic of e_x."""
    i = list(SOURCES).index("swing_m_per_px")
    return {"e_x_err_scale": fs.by_source["e_x"][i], "e_x_pooled_err_scale": fs.by_source["e_x_pooled"][i]}


def add_fit_systematics(ds: xr.Dataset, fs: FitSystematics | None) -> xr.Dataset:
    """fit_ex.nc's dataset with the systematics of :func:`fit_systematics` (unchanged for None)."""
    if fs is None:
        return ds
    what = "the tracks reduced again, then normalize, reconstruct and the fit"
    return _systematic_vars(ds, fs.by_source, what, fs.rel_sigma)


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
    out = stronge_by_source(
        rec, ds["ball"].values.astype(str), names, e_y=e_y, mu=mu, vary_e_y=vary_e_y, vary_mu=vary_mu
    )
    for q in names:  # no value, no systematic
        out[q][:, ~np.isfinite(ds[q].values)] = np.nan
    rel = rec["systematic_rel_sigma"].values
    what = "the tracks reduced again, then normalize, reconstruct and the eta^2 fit"
    return _systematic_vars(ds, out, what, rel)
