"""NetCDF input and output with units, metadata and provenance.

:func:`write_dataset` is the one way the workflow writes results: it checks that every
variable has ``units`` and ``long_name``, sets the CF-style global attributes
(Conventions, title, source, history, references) and the provenance records, and writes
atomically (a temporary file in the same directory, renamed into place), so a failed job
never leaves a half-written file, and seals it with the checksum of its contents
(:mod:`.checked`). :func:`read_dataset` verifies every byte of a file, loads it fully and checks it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from .. import __version__
from .atomic import atomic_target
from .checked import CHECKSUM_ATTR, DamagedFileError, read_sealed_csv, seal_netcdf, verify_netcdf
from .provenance import data_inputs, provenance_attrs

if TYPE_CHECKING:
    import os
    from collections.abc import Mapping

CONVENTIONS = "CF-1.10"
REFERENCES = (
    "J. R. Kensrud, A. M. Nathan and L. V. Smith, 'Oblique collisions of baseballs and "
    "softballs with a bat', Am. J. Phys. 85, 503 (2017), doi:10.1119/1.4982793"
)


class MetadataError(ValueError):
    """A dataset lacks the metadata every results file must carry."""


def check_metadata(ds: xr.Dataset, where: str = "dataset") -> None:
    """Raise :class:`MetadataError` naming every variable without ``units`` or ``long_name``.

    A variable whose values along a dimension are in different units (a study's estimates of
    several quantities) has, instead of ``units``, ``units_from``: the name of a text coordinate
    along that dimension that holds each element's unit.
    """
    missing = []
    for name, var in {**ds.data_vars, **ds.coords}.items():
        if var.dtype.kind in "OSU":  # labels: long_name only
            if "long_name" not in var.attrs:
                missing.append(f"{name}: long_name")
            continue
        if "units" not in var.attrs and "units_from" in var.attrs:  # units per element: an aligned text coordinate
            ref = ds.coords.get(var.attrs["units_from"])
            if ref is None or ref.dtype.kind not in "OSU" or not set(ref.dims) <= set(var.dims):
                missing.append(
                    f"{name}: units (its units_from {var.attrs['units_from']!r} is no text coordinate of it)"
                )
        elif "units" not in var.attrs:
            missing.append(f"{name}: units")
        if "long_name" not in var.attrs:
            missing.append(f"{name}: long_name")
    if missing:
        raise MetadataError(f"{where}: variables lack metadata: " + "; ".join(missing))


def write_dataset(
    ds: xr.Dataset,
    path: str | os.PathLike[str],
    *,
    title: str,
    rule: str,
    inputs: Mapping[str, object],
    config: dict,
    history: str | None = None,
) -> Path:
    """Write ``ds`` to NetCDF at ``path`` with metadata and provenance, atomically."""
    path = Path(path)
    check_metadata(ds, str(path))
    ds = ds.copy()
    ds.attrs = {
        **{k: v for k, v in ds.attrs.items() if not k.startswith("provenance_")},
        "Conventions": CONVENTIONS,
        "title": title,
        "source": f"ballbat {__version__}, rule {rule}",
        "history": history or f"written by ballbat {__version__} rule {rule} (times are in the workflow logs)",
        "references": REFERENCES,
        **provenance_attrs(rule, inputs, config),
    }
    encoding = {}
    for name, var in ds.variables.items():
        if name in ds.coords:  # CF: coordinates have no missing values, so no _FillValue
            encoding[name] = {"_FillValue": None}
            if var.dtype.kind in "OU":
                encoding[name]["dtype"] = str
        elif var.dtype.kind == "f":
            encoding[name] = {"_FillValue": np.nan}
        elif var.dtype.kind in "OU":
            encoding[name] = {"dtype": str}
    with atomic_target(path) as tmp:
        ds.to_netcdf(tmp, engine="netcdf4", format="NETCDF4", encoding=encoding)
        seal_netcdf(tmp)
    return path


def write_job_output(ds: xr.Dataset, job: object, output: str, title: str, config: dict | None = None) -> Path:
    """Write ``ds`` to a Snakemake job's output ``output``, with the job's provenance.

    ``job`` is the ``snakemake`` object of a rule's script: its rule name, its data inputs
    (:func:`~ballbat.pipeline.provenance.data_inputs`) and, unless ``config`` is given, its
    params are recorded.
    """
    return write_dataset(
        ds,
        job.output[output],
        title=title,
        rule=job.rule,
        inputs=data_inputs(job.input),
        config=dict(job.params) if config is None else config,
    )


def read_dataset(path: str | os.PathLike[str], require: tuple[str, ...] = ()) -> xr.Dataset:
    """Load a results file fully into memory and check the variables ``require`` names.

    The file is verified whole first (:func:`~ballbat.pipeline.checked.verify_netcdf`): a damaged
    file, or one without the workflow's provenance record (a user's own NetCDF at a results
    path), raises :class:`~ballbat.pipeline.checked.DamagedFileError` naming it.
    """
    verify_netcdf(path)
    with xr.open_dataset(path, engine="netcdf4") as ds:
        ds = ds.load()
    if "provenance_rule" not in ds.attrs:  # a NetCDF of someone else's at a path the workflow writes
        raise DamagedFileError(
            path,
            "lacks the workflow's provenance record, so none of its rules wrote it: "
            "a NetCDF of your own where the workflow keeps its results?",
        )
    ds.attrs.pop(CHECKSUM_ATTR, None)  # of the file, not of the data: a file written from ds gets its own
    missing = [v for v in require if v not in ds.variables]
    if missing:
        raise MetadataError(f"{path}: missing variable(s) {', '.join(missing)}")
    return ds


def read_table_csv(path: str | os.PathLike[str]) -> str:
    """Return the text of a CSV table the workflow wrote, verified whole (without its check line)."""
    return read_sealed_csv(path)


def atomic_write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write a text file atomically (temporary file renamed into place)."""
    path = Path(path)
    with atomic_target(path) as tmp:
        tmp.write_text(text, newline="")
    return path
