"""Stage study_batch: ``results/studies/{study}/batches/batch{n}.nc``, the replicates of one batch job.

Each replicate is the workflow's own stages in memory (:func:`ballbat.studies.replicates.run_replicate`:
simulate, render, reduce, normalize, reconstruct, fit_ex and eta^2); this stage runs a batch
of them (:func:`ballbat.studies.replicates.run_replicates`) and writes their estimates, uncertainties,
systematics and truths on :data:`BATCH_TABLE` (dims replicate x quantity; SI, each quantity's
unit in the coordinate ``units``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..pipeline.products import Var, build_dataset
from .records import PER_QUANTITY_UNITS, quantity_coords, row_labels, study_attrs
from .replicates import run_replicates
from .settings import StudySettings

if TYPE_CHECKING:
    from collections.abc import Callable

    import xarray as xr

    from ..properties import Ball, Bat

__all__ = ["BATCH_TABLE", "StudySettings", "run"]

BATCH_TABLE = {
    "value": Var(("replicate", "quantity"), None, "estimate (SI: unit of its quantity in units)", PER_QUANTITY_UNITS),
    "uncertainty": Var(
        ("replicate", "quantity"), None, "reported uncertainty of the estimate (same unit)", PER_QUANTITY_UNITS
    ),
    "truth": Var(
        ("replicate", "quantity"),
        None,
        "the same estimator on the replicate's noise-free truth (same unit)",
        PER_QUANTITY_UNITS,
    ),
    "dof": Var(("replicate", "quantity"), "1", "degrees of freedom of the uncertainty (inf: normal)"),
    "systematic": Var(
        ("replicate", "quantity"),
        None,
        "reported systematic uncertainty of the estimate (same unit; NaN: none)",
        PER_QUANTITY_UNITS,
    ),
    "calibration_effect": Var(
        ("replicate", "quantity"),
        None,
        "first-order change of the estimate under the replicate's drawn calibration: the sum over sources of "
        "its drawn error in stated uncertainties times the estimate's signed change per +1 sigma "
        "(same unit; NaN: calibration not drawn)",
        PER_QUANTITY_UNITS,
    ),
    "point": Var(("replicate",), "1", "sweep point of the replicate (index into setting)"),
    "seed_replicate": Var(("replicate",), "1", "replicate number within its point (its seeds' spawn key)"),
    "refusal": Var(
        ("replicate",),
        None,
        "why the chain refused the replicate's data (empty: it did not; a refused replicate has no estimates)",
    ),
}


def run(
    settings: StudySettings,
    batch: int,
    balls: dict[str, Ball],
    bats: dict[str, Bat],
    progress: Callable[[int, int], None] | None = None,
) -> xr.Dataset:
    """Run the replicates of batch ``batch``; return its dataset (dims replicate x quantity).

    Parameters
    ----------
    settings : StudySettings
        The study (:meth:`StudySettings.from_block`).
    batch : int
        Batch number (:meth:`StudySettings.batch_range`).
    balls, bats : dict
        Property tables.
    progress : callable, optional
        Called with (done, total) after each replicate (for the log).
    """
    records = []
    for record in run_replicates(settings, batch, balls, bats):
        records.append(record)
        if progress is not None:
            progress(len(records), len(settings.batch_range(batch)))
    table: dict[str, int] = {}
    units: dict[str, str] = {}
    for _, _, _, rows, _ in records:
        for label, r in zip(row_labels(rows), rows, strict=True):
            table.setdefault(label, len(table))
            units.setdefault(label, r["units"])
    labels = list(table)
    arrays = {
        k: np.full((len(records), len(labels)), np.nan)
        for k in ("value", "uncertainty", "truth", "dof", "systematic", "calibration_effect")
    }
    for i, (_, _, _, rows, _) in enumerate(records):
        for label, r in zip(row_labels(rows), rows, strict=True):
            for k in arrays:
                v = r.get(k)
                arrays[k][i, table[label]] = np.nan if v is None else float(v)
    values = {
        **arrays,
        "point": np.array([p for _, p, _, _, _ in records], dtype=np.int64),
        "seed_replicate": np.array([r for _, _, r, _, _ in records], dtype=np.int64),
        "refusal": np.array([why for *_, why in records], dtype=str),
    }
    coords = quantity_coords(labels, [lab.split(":") for lab in labels], [units[lab] for lab in labels])
    coords["replicate"] = (
        Var(("replicate",), "1", "replicate number over the whole study"),
        np.array([g for g, *_ in records], dtype=np.int64),
    )
    return build_dataset(BATCH_TABLE, values, coords, study_attrs(settings, batch))
