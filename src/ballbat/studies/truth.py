"""The truth a replicate's estimate is judged against: the estimators on a large noise-free experiment."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..pipeline.products import Var, build_dataset
from .records import (
    PER_QUANTITY_UNITS,
    _grid_coords,
    _setting_column,
    quantity_coords,
    row_labels,
    study_attrs,
    sweep_table,
)
from .replicates import run_replicate
from .settings import StudySettings

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    from ..properties import Ball, Bat


#: Quantities judged against the truth of their own replicate (the same impacts noise-free):
#: the largest tan(psi - theta) of the impacts is a property of those impacts only.
CONDITIONAL_TRUTH = ("mu_k_lower_bound",)


def population_truth(settings: StudySettings, point: int, balls: dict[str, Ball], bats: dict[str, Bat]) -> dict:
    """Truth of every quantity for the experiment design at sweep point ``point`` (SI; :func:`_population_rows`).

    Returns
    -------
    dict
        ``quantity:ball:bat`` label -> truth.
    """
    rows = _population_rows(settings, point, balls, bats)
    return dict(zip(row_labels(rows), (r["truth"] for r in rows), strict=True))


def truth_scale(settings: StudySettings, point: int) -> int:
    """How many times the truth job's experiment repeats a replicate's design at sweep point ``point``.

    :meth:`StudySettings.truth_counts` (one rule for the truth's size). The truth's own
    sampling error is about that of a replicate's noise-free estimate over the square root of
    this number, for every pair alike (:func:`coverage`).
    """
    return settings.truth_counts(point)[0]


def _population_rows(settings: StudySettings, point: int, balls: dict[str, Ball], bats: dict[str, Bat]) -> list[dict]:
    """Return the rows of the design's large noise-free experiment at sweep point ``point`` (:func:`run_replicate`'s).

    A pooled e_x, a slope or eta^2 describes the population the impacts are drawn from (the
    bats in the design's proportions, psi and bat speed drawn as configured), not the handful
    of impacts of one replicate: where the model does not describe each bat exactly (pooled
    over bats of different e_x, a straight line through curved data), the impacts a replicate
    happens to draw move the estimate as much as the noise does, and the standard error from
    the scatter accounts for both. The truth is therefore the estimator on a large noise-free
    experiment of the same design (about ``settings.truth_impacts`` impacts per ball and bat on
    average, in the design's proportions: :meth:`StudySettings.truth_counts`), the same for
    every replicate of the point. e_x of one bat is the same either way (the model is exact);
    :data:`CONDITIONAL_TRUTH` keep their own.
    """
    ds = settings.point_dataset(point)
    ds["synthetic"]["impacts"] = settings.truth_counts(point)[1]
    # the design's truth is the tables' bat (a drawn one's e_x is the same: drawing moves the analysis, not e_x)
    seed = int(np.random.SeedSequence(settings.seed, spawn_key=(2**31 - 1, point)).generate_state(1)[0])
    big = replace(settings, seed=seed, draw_properties=False)
    return run_replicate(big, ds, 0, balls, bats, check=False)


#: The truth file of a study (``results/{study}/truth.nc``; dims point x quantity).
TRUTH_TABLE = {
    "truth": Var(
        ("point", "quantity"),
        None,
        "the estimator on the design's large noise-free experiment (SI: unit of its quantity in units; NaN: none)",
        PER_QUANTITY_UNITS,
    ),
    "setting": Var(("point",), "1", "value of the swept setting (NaN: no sweep)"),
    "truth_scale": Var(
        ("point",), "1", "how many times the truth's experiment repeats a replicate's design (truth_scale())"
    ),
}


def truth_dataset(
    settings: StudySettings, balls: dict[str, Ball], bats: dict[str, Bat], points: Sequence[int] | None = None
) -> xr.Dataset:
    """:func:`population_truth` of every sweep point, as a dataset (its own job: it runs beside the batches).

    ``points``: only these sweep points (one job per point, :func:`merge_truths` joins them);
    None: every point.

    Returns
    -------
    xarray.Dataset
        ``truth`` (point x quantity, labels as the batches'), ``setting``.
    """
    points = list(range(settings.n_points)) if points is None else [int(p) for p in points]
    rows_of = [_population_rows(settings, p, balls, bats) for p in points]
    truths = [dict(zip(row_labels(rows), (r["truth"] for r in rows), strict=True)) for rows in rows_of]
    units = {lab: r["units"] for rows in rows_of for lab, r in zip(row_labels(rows), rows, strict=True)}
    labels = list(dict.fromkeys(lab for t in truths for lab in t))
    names, table = sweep_table(study_attrs(settings))
    table = table[points]
    values = {
        "truth": np.array([[np.nan if t.get(lab) is None else float(t[lab]) for lab in labels] for t in truths]),
        "setting": _setting_column(names, table),
        "truth_scale": np.array([truth_scale(settings, p) for p in points], dtype=float),
    }
    coords = quantity_coords(labels, [lab.split(":") for lab in labels], [units[lab] for lab in labels])
    coords["point"] = (Var(("point",), "1", "sweep point"), np.asarray(points, dtype=np.int64))
    coords.update(_grid_coords(names, table))
    return build_dataset(
        TRUTH_TABLE, values, coords, {**study_attrs(settings), "truth_impacts": settings.truth_impacts}
    )


def merge_truths(parts: Iterable[xr.Dataset]) -> xr.Dataset:
    """Join the truth files of single sweep points (:func:`truth_dataset` with ``points``) into the study's.

    Quantities are aligned by label (NaN where a point has none); every point of the study must
    be there exactly once, or a :class:`ValueError` names the missing or repeated ones.
    """
    parts = list(parts)
    if not parts:
        raise ValueError("no truth files to merge")
    n = int(np.asarray(parts[0].attrs["sweep_values"]).size // max(1, len(sweep_table(parts[0].attrs)[0])))
    have = [int(p) for part in parts for p in part["point"].values]
    if sorted(have) != list(range(n)):
        missing = sorted(set(range(n)) - set(have))
        repeated = sorted({p for p in have if have.count(p) > 1})
        raise ValueError(f"truth files of {n} sweep points: missing {missing}, repeated {repeated}")
    labels = list(dict.fromkeys(lab for b in parts for lab in b["quantity"].values.tolist()))
    aligned = [b.reindex(quantity=labels) for b in parts]
    out = xr.concat(aligned, dim="point", data_vars="minimal", coords="minimal", compat="override", join="outer")
    out = out.sortby("point")
    out.attrs = {k: v for k, v in parts[0].attrs.items() if k in (*_TRUTH_ATTRS, "truth_impacts")}
    return out


#: The attributes a truth file carries from its study (:func:`_attrs`).
_TRUTH_ATTRS = ("study_seed", "replicates_per_point", "sweep_parameter", "sweep_values")


def truths_from_dataset(ds: xr.Dataset) -> list[dict]:
    """Return the per-point ``label -> truth`` mappings of :func:`truth_dataset` (what :func:`coverage` takes)."""
    labels = ds["quantity"].values.astype(str)
    return [dict(zip(labels, map(float, row), strict=True)) for row in ds["truth"].values]


def truth_scales_from_dataset(ds: xr.Dataset) -> np.ndarray:
    """Return the per-point ``truth_scale`` of :func:`truth_dataset` (what :func:`coverage` takes as ``truth_scale``).

    Raises
    ------
    ValueError
        A truth file without it (written before it was recorded): run its truth jobs again.
    """
    if "truth_scale" not in ds:
        raise ValueError(
            f"{ds.encoding.get('source', 'the truth file')}: no truth_scale variable (written by an older ballbat); "
            "delete the study's truth files and run its truth jobs again"
        )
    return ds["truth_scale"].values.astype(float)


def run(
    settings: StudySettings, balls: dict[str, Ball], bats: dict[str, Bat], points: Sequence[int] | None = None
) -> xr.Dataset:
    """Run the truth stage: the design's truth at the sweep ``points`` (None: every point), :func:`truth_dataset`."""
    return truth_dataset(settings, balls, bats, points)
