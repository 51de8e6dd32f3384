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
    INSTRUMENT_SOURCES,
    PROPERTY_SHIFTED,
    PROPERTY_UNITS,
    SHIFT_UNITS,
    SHIFTED,
    SIDES,
    SOURCES,
    Shifts,
)

#: Prefix of the ``systematic`` coordinate's long name.
_COORD_WHAT = "calibration source of a systematic: "

if TYPE_CHECKING:
    import xarray as xr


def _coords(names: list[str] | None = None, what: dict[str, str] | None = None, long_name: str | None = None) -> dict:
    """Return the ``systematic`` coordinate: the sources ``names`` (default :data:`SOURCES`), described."""
    names = list(SOURCES) if names is None else list(names)
    what = {**SOURCES, **{k: v[1] for k, v in INSTRUMENT_SOURCES.items()}, **(what or {})}
    text = long_name or _COORD_WHAT + "; ".join(f"{k}: {what.get(k, k)}" for k in names)
    return {"systematic": (("systematic",), np.array(names, dtype=str), {"long_name": text})}


def _rel_sigma_var(rel: np.ndarray) -> tuple:
    return (
        ("systematic",),
        np.asarray(rel, dtype=float),
        {
            "units": "1",
            "long_name": "relative standard uncertainty of each calibration source (0: none stated)"
            + (
                "; NaN: an absolute one (angle_offset: its sigma is in the source's description)"
                if np.isnan(rel).any()
                else ""
            ),
        },
    )


def add_shifts(ds: xr.Dataset, shifts: Shifts | None, what: dict[str, str] | None = None) -> xr.Dataset:
    """Return reduce.nc's (ingest.nc's) dataset with the shifts of :func:`reduce_shifts` (unchanged for None).

    ``what`` describes sources beyond :data:`SOURCES` and :data:`~ballbat.systematics.INSTRUMENT_SOURCES`.
    """
    if shifts is None:
        return ds
    out = ds.assign_coords(
        **_coords(shifts.names, what),
        shift=(
            ("shift",),
            np.array(SIDES, dtype=np.int8),
            {"units": "1", "long_name": "calibration shifted by this many standard uncertainties"},
        ),
    )
    new = {"systematic_rel_sigma": _rel_sigma_var(shifts.rel_sigma)}
    for k in SHIFTED:
        base = k.removesuffix("_err")
        what = f"the standard uncertainty of {base}" if k.endswith("_err") else base
        new[f"{k}_shift"] = (
            ("systematic", "shift", "impact"),
            shifts.shift[k],
            {
                "units": SHIFT_UNITS[base],
                "long_name": f"change of {what} when the tracks are reduced with one calibration shifted "
                "(systematic; 0 where the source has no uncertainty)",
                "ballbat_role": "systematic",
            },
        )
    return out.assign(new)  # one merge for all of them, in this order (one per variable cost a study's replicate more)


def append_sources(
    ds: xr.Dataset, names: list[str], rel: np.ndarray, props: dict[str, np.ndarray], what: dict[str, str]
) -> xr.Dataset:
    """Return reconstruct.nc's dataset with property sources appended to its ``systematic`` dimension.

    Parameters
    ----------
    ds : xarray.Dataset
        The reconstructed impacts, with or without sources already (tracks' or instruments').
    names, rel
        The new sources and their relative standard uncertainties.
    props : dict
        Per :data:`~ballbat.systematics.PROPERTY_SHIFTED` name, the shifts (new source, side, impact).
    what : dict
        Each new source's description (for the coordinate's long name).

    Returns
    -------
    xarray.Dataset
        The measured values' shifts are 0 for a property source, the properties' shifts 0 for
        the earlier sources; nothing is added for no new source.
    """
    if not names:
        return ds
    n = ds.sizes["impact"]
    zeros = np.zeros((len(names), len(SIDES), n))
    if "systematic" not in ds.coords:
        out = add_shifts(ds, Shifts(np.asarray(rel, float), {k: zeros for k in SHIFTED}, list(names)), what)
        old = 0
    else:
        old = ds.sizes["systematic"]
        text = ds["systematic"].attrs["long_name"] + "; " + "; ".join(f"{k}: {what.get(k, k)}" for k in names)
        kept = {k: ds[f"{k}_shift"].values for k in SHIFTED}
        shifts = Shifts(
            np.concatenate([ds["systematic_rel_sigma"].values, rel]),
            {k: np.concatenate([v, zeros]) for k, v in kept.items()},
            [*(str(v) for v in ds["systematic"].values), *names],
        )
        out = ds.drop_vars([f"{k}_shift" for k in SHIFTED] + ["systematic_rel_sigma", "systematic"])
        out = add_shifts(out, shifts)
        out["systematic"].attrs["long_name"] = text
    for k in PROPERTY_SHIFTED:
        per = np.concatenate([np.zeros((old, len(SIDES), n)), props[k]])
        out[f"{k}_shift"] = (
            ("systematic", "shift", "impact"),
            per,
            {
                "units": PROPERTY_UNITS[k],
                "long_name": f"change of the impact's {k} when one bat or ball property is moved by one standard "
                "uncertainty (systematic; 0 for the other sources)",
                "ballbat_role": "systematic",
            },
        )
    return out


def combine_sources(by_source: np.ndarray) -> np.ndarray:
    """Return the systematic error from each source's (first axis) signed shift: every source in quadrature."""
    return np.sqrt(np.sum(by_source**2, axis=0))


def systematic_vars(
    ds: xr.Dataset,
    by_source: dict[str, np.ndarray],
    what: str,
    rel: np.ndarray,
    source: xr.DataArray | None = None,
) -> xr.Dataset:
    """``ds`` with ``<q>_syst_by_source``, ``<q>_syst`` and (where ``<q>_err`` is) ``<q>_err_total``.

    ``source``: the impacts' ``systematic`` coordinate (names and long name; None: :data:`SOURCES`).
    """
    if "systematic" in ds.coords:
        out = ds
    elif source is None:
        out = ds.assign_coords(**_coords())
    else:
        out = ds.assign_coords(**_coords(list(source.values.astype(str)), long_name=source.attrs.get("long_name")))
    new = {"systematic_rel_sigma": _rel_sigma_var(rel)}
    for q, per in by_source.items():
        dims, attrs = ds[q].dims, ds[q].attrs
        units = {"units": attrs["units"]} if "units" in attrs else {}
        syst = combine_sources(per)
        new[f"{q}_syst_by_source"] = (
            ("systematic", *dims),
            per,
            {
                **units,
                "long_name": f"systematic error of {q} from each calibration source: half the change of {q} "
                f"between that calibration at +1 and at -1 standard uncertainty ({what})",
                "ballbat_role": "systematic",
            },
        )
        new[f"{q}_syst"] = (
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
            new[f"{q}_err_total"] = (
                dims,
                np.hypot(ds[f"{q}_err"].values, syst),
                {**units, "long_name": f"standard error and systematic error of {q} in quadrature"},
            )
    return out.assign(new)  # one merge, in this order
