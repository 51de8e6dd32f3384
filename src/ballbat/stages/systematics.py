"""The calibration systematics in the result files: reduce.nc's shifts, fit_ex.nc's and stronge.nc's systematics.

The computation is :mod:`ballbat.systematics` (the sources, the tracks reduced again, the shifted
impacts); the stages refit every quantity at +-1 sigma of each source
(:func:`ballbat.stages.fit_ex.fit_systematics`, :func:`ballbat.stages.stronge.stronge_systematics`),
and this module adds the variables to their Datasets: ``<name>_shift`` (reduce.nc),
``<q>_syst_by_source``, ``<q>_syst`` and ``<q>_err_total`` (fit_ex.nc, stronge.nc).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..systematics import (
    SHIFT_UNITS,
    SHIFTED,
    SIDES,
    SOURCES,
    Shifts,
)

if TYPE_CHECKING:
    import xarray as xr


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


def combine_sources(by_source: np.ndarray) -> np.ndarray:
    """Return the systematic error from each source's (first axis) signed shift: every source in quadrature."""
    return np.sqrt(np.sum(by_source**2, axis=0))


def systematic_vars(ds: xr.Dataset, by_source: dict[str, np.ndarray], what: str, rel: np.ndarray) -> xr.Dataset:
    """``ds`` with ``<q>_syst_by_source``, ``<q>_syst`` and (where ``<q>_err`` is) ``<q>_err_total``."""
    out = ds.assign_coords(**_coords()) if "systematic" not in ds.coords else ds
    out["systematic_rel_sigma"] = _rel_sigma_var(rel)
    for q, per in by_source.items():
        dims, attrs = ds[q].dims, ds[q].attrs
        units = {"units": attrs["units"]} if "units" in attrs else {}
        syst = combine_sources(per)
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
