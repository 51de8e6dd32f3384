"""Stage ingest: ``results/{dataset}/ingest.nc``, a measured file's impacts, checked and in SI.

:data:`INGEST_TABLE` declares the file: the impacts table of :mod:`.impacts` (an uncertainty only
where the file gives it) and the file's own ids, places and exclusions. :func:`run` reads and checks
the file (:func:`ballbat.ingest.read_measured`) and assembles it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..ingest import MEASURED_COLUMNS, read_measured
from ..kinematics import ImpactFlag
from ..pipeline.products import Var, build_dataset, flag_attrs
from ..systematics import INSTRUMENT_SOURCES, instrument_shifts
from .impacts import IMPACTS, impact_coords
from .systematics import add_shifts

if TYPE_CHECKING:
    import os
    from collections.abc import Mapping

#: The variables of ingest.nc, in order (``*_err`` only where the file has the column).
INGEST_TABLE = {
    **IMPACTS,
    "impact_id": Var(("impact",), None, "impact id given in the source file"),
    "source_row": Var(
        ("impact",), None, "where the impact is in the source file (CSV line number, header = 1; NetCDF index)"
    ),
    "ingest_flag": Var(
        ("impact",), "1", "exclusion flag set when the file was read (0: usable)", flag_attrs(ImpactFlag)
    ),
    "ingest_flag_reason": Var(("impact",), None, "why the impact is excluded (ok if it is not)"),
}


@dataclass(frozen=True)
class IngestSettings:
    """Settings of the ingest stage (the impacts file and the property tables are inputs).

    Attributes
    ----------
    calibration : dict
        The instruments' calibration uncertainties the dataset states (config
        ``datasets.<name>.calibration``: ``speed_scale_pct``, ``spin_scale_pct``,
        ``angle_offset_deg``; :func:`ballbat.systematics.instrument_shifts`); empty: none stated.
    """

    calibration: dict

    @classmethod
    def from_config(cls, config: dict, dataset: str | None = None) -> IngestSettings:
        """Return the workflow's settings from the validated config (``dataset``: whose calibration)."""
        if dataset is None:
            return cls(calibration={})
        return cls.from_params({"calibration": config["datasets"][dataset].get("calibration", {})})

    @classmethod
    def from_params(cls, params: Mapping) -> IngestSettings:
        """Return the workflow's settings from the ingest rule's params (``calibration``)."""
        return cls(calibration=dict(params["calibration"]))


def run(
    settings: IngestSettings,
    impacts: str | os.PathLike[str],
    balls: str | os.PathLike[str],
    bats: str | os.PathLike[str],
) -> xr.Dataset:
    """Read and check a measured dataset (``impacts``, with the property tables ``balls`` and ``bats``).

    Returns the impacts in SI; the warnings are the attribute ``ingest_warnings`` (one per line,
    :func:`warnings`). Raises :class:`~ballbat.properties.InputError` listing every problem that
    stops the dataset (bad property tables included). Impacts psi cannot use stay in the output
    with ``ingest_flag`` > 0 and the reason in ``ingest_flag_reason``.
    """
    got = read_measured(impacts, balls, bats)
    cols, m = got.columns, got.measured
    values = {}
    for c, (si, factor) in MEASURED_COLUMNS.items():
        values[si] = getattr(m, si)
        if f"{c}_err" in cols:
            values[f"{si}_err"] = cols[f"{c}_err"] * factor
    values["impact_id"] = cols["impact_id"].astype(str)
    values["source_row"] = cols["label"].astype(str)
    values["ingest_flag"] = got.flag
    values["ingest_flag_reason"] = got.reason
    given = {name: var for name, var in INGEST_TABLE.items() if name in values}  # the *_err columns are optional
    attrs = {
        "source_file": str(impacts),
        "n_impacts": len(got.ball),
        "n_excluded": int((got.flag != 0).sum()),
        "n_warnings": len(got.warnings),
        "ingest_warnings": "\n".join(got.warnings),
    }
    ds = build_dataset(given, values, coords=impact_coords(got.ball, got.bat), attrs=attrs)
    return add_shifts(ds, instrument_shifts(values, settings.calibration), calibration_what(settings.calibration))


def calibration_what(calibration: dict) -> dict[str, str]:
    """Each stated instrument source's description with its stated uncertainty (the coordinate's long name)."""
    out = {}
    for source, (key, what) in INSTRUMENT_SOURCES.items():
        if calibration.get(key):
            unit = "deg" if key.endswith("_deg") else "%"
            out[source] = what.split(" (")[0] + f" (calibration.{key} = {calibration[key]:g} {unit})"
    return out


def warnings(ds: xr.Dataset) -> list[str]:
    """Return the warnings of ingest.nc, one per entry."""
    text = ds.attrs["ingest_warnings"]
    return text.split("\n") if text else []


def excluded_listing(ds: xr.Dataset) -> list[str]:
    """One line per excluded impact: id, where it is in the file, and why."""
    from ..analysis import impact_labels

    bad = np.flatnonzero(ds["ingest_flag"].values != 0)
    labels = impact_labels(ds)
    return [f"{labels[i]}: {ds['ingest_flag_reason'].values[i]}" for i in bad]
