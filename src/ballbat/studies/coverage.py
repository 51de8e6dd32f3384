"""Aggregation: the coverage of every uncertainty over a study's replicates (``coverage.nc``, ``coverage.csv``)."""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..pipeline.products import Var, build_dataset
from .records import (
    PER_QUANTITY_UNITS,
    _grid_coords,
    _setting_column,
    combined_dof,
    display_unit,
    point_label,
    sweep_table,
)
from .truth import CONDITIONAL_TRUTH, truth_scales_from_dataset, truths_from_dataset

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence


def combine(batches: Iterable[xr.Dataset]) -> xr.Dataset:
    """Concatenate batch datasets along ``replicate`` (sorted; quantities aligned by label)."""
    batches = list(batches)
    if not batches:
        raise ValueError("no batches to combine")
    labels = list(dict.fromkeys(lab for b in batches for lab in b["quantity"].values.tolist()))
    parts = [b.reindex(quantity=labels) for b in batches]
    out = xr.concat(parts, dim="replicate", data_vars="minimal", coords="minimal", compat="override", join="outer")
    return out.sortby("replicate")


def _t(q: float, dof: np.ndarray) -> np.ndarray:
    """Return the two-sided ``q`` quantile of Student's t with ``dof`` (normal where infinite, NaN where not positive).

    ``scipy.special``'s ``ndtri`` and ``stdtrit``: the numbers of ``scipy.stats.norm.ppf`` and
    ``t.ppf``, without importing scipy.stats (0.35 s, at the end of every study).
    """
    from scipy.special import ndtri, stdtrit

    dof = np.asarray(dof, dtype=float)
    z = ndtri(0.5 + q / 2)
    with np.errstate(all="ignore"):
        t = stdtrit(np.where(np.isfinite(dof) & (dof > 0), dof, 1.0), 0.5 + q / 2)
    return np.where(np.isfinite(dof), np.where(dof > 0, t, np.nan), z)


#: The coverage table (dims point x quantity).
COVERAGE_TABLE = {
    "n_replicates": Var(("point", "quantity"), "1", "replicates with a value, an uncertainty and a truth"),
    "n_refused": Var(
        ("point", "quantity"),
        "1",
        "replicates of the point whose data the chain refused (a check's false alarm; not in n_replicates)",
    ),
    "bias_over_se": Var(("point", "quantity"), "1", "mean of (value - truth) / uncertainty"),
    "bias_over_se_err": Var(
        ("point", "quantity"),
        "1",
        "standard error of bias_over_se: the replicates' scatter and the truth's own sampling error "
        "(truth_error_over_se) in quadrature",
    ),
    "truth_error_over_se": Var(
        ("point", "quantity"),
        "1",
        "sampling error of the design's truth (its large noise-free experiment) over the mean uncertainty "
        "(NaN: judged against each replicate's own truth, or no truth_scale)",
    ),
    "spread_over_se": Var(("point", "quantity"), "1", "standard deviation of (value - truth) / mean uncertainty"),
    "spread_over_se_err": Var(("point", "quantity"), "1", "standard error of spread_over_se"),
    "coverage_68": Var(("point", "quantity"), "1", "fraction of 68 % intervals (t quantile) that cover the truth"),
    "coverage_68_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_68"),
    "coverage_95": Var(("point", "quantity"), "1", "fraction of 95 % intervals (t quantile) that cover the truth"),
    "coverage_95_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_95"),
    "mean_uncertainty": Var(
        ("point", "quantity"), None, "mean reported uncertainty (SI: unit of the quantity in units)", PER_QUANTITY_UNITS
    ),
    "spread": Var(
        ("point", "quantity"), None, "standard deviation of value - truth (SI: unit in units)", PER_QUANTITY_UNITS
    ),
    "mean_value": Var(("point", "quantity"), None, "mean estimate (SI: unit in units)", PER_QUANTITY_UNITS),
    "mean_truth": Var(("point", "quantity"), None, "mean truth (SI: unit in units)", PER_QUANTITY_UNITS),
    "mean_dof": Var(("point", "quantity"), "1", "mean degrees of freedom of the uncertainty"),
    "n_systematic": Var(("point", "quantity"), "1", "replicates of n_replicates with a systematic uncertainty"),
    "mean_systematic": Var(
        ("point", "quantity"), None, "mean reported systematic uncertainty (SI: unit in units)", PER_QUANTITY_UNITS
    ),
    "coverage_68_combined": Var(
        ("point", "quantity"),
        "1",
        "fraction of 68 % combined intervals (t quantile x sqrt(uncertainty^2 + systematic^2), Welch-Satterthwaite "
        "degrees of freedom) that cover the truth "
        "(NaN: no systematic)",
    ),
    "coverage_68_combined_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_68_combined"),
    "coverage_95_combined": Var(
        ("point", "quantity"),
        "1",
        "fraction of 95 % combined intervals (t quantile x sqrt(uncertainty^2 + systematic^2), Welch-Satterthwaite "
        "degrees of freedom) that cover the truth "
        "(NaN: no systematic)",
    ),
    "coverage_95_combined_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_95_combined"),
    "n_calibrated": Var(("point", "quantity"), "1", "replicates of n_replicates with a drawn calibration's effect"),
    "bias_over_se_calibrated": Var(
        ("point", "quantity"),
        "1",
        "mean of (value + calibration_effect - truth) / uncertainty: the bias with the drawn calibration's "
        "first-order effect taken out (NaN: calibration not drawn)",
    ),
    "bias_over_se_calibrated_err": Var(
        ("point", "quantity"), "1", "standard error of bias_over_se_calibrated (as bias_over_se_err)"
    ),
    "spread_over_se_calibrated": Var(
        ("point", "quantity"),
        "1",
        "standard deviation of value + calibration_effect - truth / mean uncertainty (NaN: calibration not drawn)",
    ),
    "spread_over_se_calibrated_err": Var(("point", "quantity"), "1", "standard error of spread_over_se_calibrated"),
    "coverage_68_calibrated": Var(
        ("point", "quantity"),
        "1",
        "fraction of 68 % statistical intervals around value + calibration_effect that cover the truth "
        "(NaN: calibration not drawn)",
    ),
    "coverage_68_calibrated_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_68_calibrated"),
    "coverage_95_calibrated": Var(
        ("point", "quantity"),
        "1",
        "fraction of 95 % statistical intervals around value + calibration_effect that cover the truth "
        "(NaN: calibration not drawn)",
    ),
    "coverage_95_calibrated_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_95_calibrated"),
    "setting": Var(("point",), "1", "value of the swept setting (NaN: no sweep, or a grid: grid_setting)"),
}


#: Fewest replicates that judge a coverage: the binomial standard error of a 95 % coverage from
#: n replicates is sqrt(0.95 x 0.05 / n), 2.2 points at n = 100. Intervals 16 % too narrow
#: (1.645 instead of 1.96 standard errors) cover 90 %, which 100 replicates tell from 95 % at
#: 2.3 standard errors; fewer cannot, and their table gets a warning (``coverage_warning``).
MIN_COVERAGE_REPLICATES = 100


def coverage_warning(n: int) -> str:
    """Return the warning a quantity with ``n`` replicates gets in the coverage table ("" when enough)."""
    if n >= MIN_COVERAGE_REPLICATES:
        return ""
    se = 100 * math.sqrt(0.95 * 0.05 / max(n, 1))
    return (
        f"only {n} replicates: a 95 % coverage is known to +-{se:.1f} points (binomial), too coarse to tell "
        f"honest intervals from intervals 16 % too narrow (90 % coverage); use at least {MIN_COVERAGE_REPLICATES}"
    )


class EmptySweepPoint(ValueError):
    """A sweep point at which no replicate gave a usable estimate of any quantity."""


def _interval_columns(ok: np.ndarray, d: np.ndarray, e: np.ndarray, dof: np.ndarray, tag: str = "") -> dict:
    """Return bias, spread and 68/95 % coverage of ``d`` (replicate x quantity in, a row per quantity out).

    ``ok``: the replicates to judge; ``d``: estimate - truth; ``e``: the statistical
    uncertainty, ``dof`` its degrees of freedom. ``tag`` goes into every column's name before
    ``_err`` (``"_calibrated"``: the columns of value + calibration_effect, the value a lab
    with the true calibration would get, so that the drawn calibration's spread, which the
    statistical error does not claim, leaves the bias and the coverage).
    """
    n = ok.sum(axis=0)
    col = {}
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a quantity no replicate judged: NaN, said by n
        d = np.where(ok, d, np.nan)
        z = d / np.where(ok, e, np.nan)
        col["bias_over_se"] = np.nanmean(z, axis=0)
        col["bias_over_se_err"] = np.nanstd(z, axis=0, ddof=1) / np.sqrt(n)
        ratio = np.nanstd(d, axis=0, ddof=1) / np.nanmean(np.where(ok, e, np.nan), axis=0)
        col["spread_over_se"] = ratio
        col["spread_over_se_err"] = ratio / np.sqrt(2.0 * np.maximum(n - 1, 1))
        for q in (68, 95):
            frac = np.where(ok, np.abs(d) <= _t(q / 100, dof) * e, False).sum(axis=0) / n
            col[f"coverage_{q}"] = frac
            col[f"coverage_{q}_err"] = np.sqrt(frac * (1 - frac) / n)
    return {(k[:-4] + tag + "_err" if k.endswith("_err") else k + tag): v for k, v in col.items()}


def _empty_point(p: int, what: str, n: int) -> EmptySweepPoint:
    """Return the error of sweep point ``p`` (``what``: its settings) whose ``n`` replicates estimated nothing."""
    return EmptySweepPoint(
        f"sweep point {p}{f' ({what})' if what else ''}: none of its {n} replicates gave a "
        "usable estimate (value, uncertainty and truth) of any quantity; the setting is beyond what the "
        "chain can fit: drop the point or change it"
    )


def _combined_columns(ok: np.ndarray, d: np.ndarray, e: np.ndarray, syst: np.ndarray, dof: np.ndarray) -> dict:
    """Return the combined interval's columns (statistical and systematic in quadrature) of one sweep point.

    Only where a systematic is reported: a quantity without one gets NaN, not the statistical
    coverage again. ``d``: estimate minus truth; ``e``, ``syst``, ``dof``: per replicate and quantity.
    """
    out = {}
    oks = ok & np.isfinite(syst) & (syst >= 0)
    ns = oks.sum(axis=0)
    out["n_systematic"] = ns
    s_used = np.where(oks, syst, 0.0)
    out["mean_systematic"] = s_used.sum(axis=0) / np.where(ns > 0, ns, np.nan)
    combined = np.hypot(e, s_used)
    dof_combined = combined_dof(e, s_used, dof)
    for q in (68, 95):
        half = _t(q / 100, dof_combined) * combined
        frac = np.where(oks, np.abs(d) <= half, False).sum(axis=0) / np.where(ns > 0, ns, np.nan)
        out[f"coverage_{q}_combined"] = frac
        out[f"coverage_{q}_combined_err"] = np.sqrt(frac * (1 - frac) / ns)
    return out


def coverage(
    rep: xr.Dataset, truths: Sequence[dict] | None = None, truth_scale: Sequence[float] | None = None
) -> xr.Dataset:
    """Coverage of every quantity at every sweep point (from :func:`combine`'s replicates).

    ``truths``: per sweep point, the design's truth of each quantity (:func:`population_truth`);
    None judges every estimate against its own replicate's truth. ``truth_scale``: per sweep
    point, how many times the truth's experiment repeats a replicate's design
    (:func:`truth_scale`). The design's truth is itself an estimate from a finite experiment:
    its sampling error is about the spread of the replicates' own noise-free estimates (their
    ``truth``) over the square root of that number. It is not negligible against a bias of a
    tenth of a standard error (up to 0.05-0.08 standard errors at 30-60 impacts per bat and
    10000 per truth, where the noise-free estimate scatters as much as the noisy one), so it
    goes into the bias's standard error (``truth_error_over_se``).

    A point at which no replicate
    has a usable estimate of any quantity raises :class:`EmptySweepPoint` naming it; a quantity
    with fewer than :data:`MIN_COVERAGE_REPLICATES` replicates gets a warning (``warning``).
    """
    swept, table = sweep_table(rep.attrs)
    npt, nq = table.shape[0], rep.sizes["quantity"]
    out = {k: np.full((npt, nq), np.nan) for k in COVERAGE_TABLE if k != "setting"}
    point = rep["point"].values
    syst_all = rep["systematic"].values if "systematic" in rep else np.full(rep["value"].shape, np.nan)
    eff_all = rep["calibration_effect"].values if "calibration_effect" in rep else np.full(rep["value"].shape, np.nan)
    refused = rep["refusal"].values.astype(str) != "" if "refusal" in rep else np.zeros(point.size, dtype=bool)
    for p in range(npt):
        sel = point == p
        v, e, t, dof = (rep[k].values[sel] for k in ("value", "uncertainty", "truth", "dof"))
        syst, eff = syst_all[sel], eff_all[sel]
        own = t
        use = np.zeros(t.shape[1], dtype=bool)
        if truths is not None:
            labels = rep["quantity"].values.astype(str)
            names = rep["quantity_name"].values.astype(str)
            pop = np.array([truths[p].get(lab, np.nan) for lab in labels])
            use = np.array([nm not in CONDITIONAL_TRUTH for nm in names])
            t = np.where(use[None, :], pop[None, :], t)
        ok = np.isfinite(v) & np.isfinite(e) & np.isfinite(t) & (e > 0)
        n = ok.sum(axis=0)
        if not n.any():
            raise _empty_point(p, point_label(swept, table[p]) if swept else "", int(sel.sum()))
        out["n_replicates"][p] = n
        out["n_refused"][p] = refused[sel].sum()
        okc = ok & np.isfinite(eff)
        out["n_calibrated"][p] = okc.sum(axis=0)
        for k, col in {
            **_interval_columns(ok, v - t, e, dof),
            **_interval_columns(okc, v + eff - t, e, dof, "_calibrated"),
        }.items():
            out[k][p] = col
        if truth_scale is not None:
            te = _truth_error_over_se(ok & use[None, :], own, e, float(truth_scale[p]))
            out["truth_error_over_se"][p] = te
            for k in ("bias_over_se_err", "bias_over_se_calibrated_err"):
                out[k][p] = np.hypot(out[k][p], np.where(np.isfinite(te), te, 0.0))
        with np.errstate(all="ignore"):
            d = np.where(ok, v - t, np.nan)
            out["spread"][p] = np.nanstd(d, axis=0, ddof=1)
            out["mean_uncertainty"][p] = np.nanmean(np.where(ok, e, np.nan), axis=0)
            for k, col in _combined_columns(ok, d, e, syst, dof).items():
                out[k][p] = col
            out["mean_value"][p] = np.nanmean(np.where(ok, v, np.nan), axis=0)
            out["mean_truth"][p] = np.nanmean(np.where(ok, t, np.nan), axis=0)
            out["mean_dof"][p] = np.nanmean(np.where(ok, dof, np.nan), axis=0)
    out["setting"] = _setting_column(swept, table)
    coords = {k: _copy_coord(rep, k) for k in ("quantity", "quantity_name", "ball", "bat", "units")}
    coords["point"] = (Var(("point",), "1", "sweep point"), np.arange(npt, dtype=np.int64))
    coords.update(_grid_coords(swept, table))
    from ..compare import STANDARD_ERROR, UNCERTAINTY_NOTES

    kinds = np.array([UNCERTAINTY_NOTES.get(str(q), STANDARD_ERROR) for q in rep["quantity_name"].values])
    coords["error_kind"] = (Var(("quantity",), None, "what the quantity's uncertainty is"), kinds)
    warn = np.array([[coverage_warning(int(n)) for n in row] for row in out["n_replicates"]], dtype=str)
    coords["warning"] = (Var(("point", "quantity"), None, "why the coverage cannot be judged (empty: it can)"), warn)
    attrs = {k: rep.attrs[k] for k in ("study_seed", "replicates_per_point", "sweep_parameter") if k in rep.attrs}
    return build_dataset(COVERAGE_TABLE, out, coords, attrs)


def _truth_error_over_se(ok: np.ndarray, own: np.ndarray, e: np.ndarray, scale: float) -> np.ndarray:
    """Return the sampling error of a design's truth over the mean uncertainty (per quantity; NaN where ``ok`` has < 2).

    ``own``: each replicate's own noise-free estimate; the truth's experiment is ``scale`` times
    a replicate's, so its estimate scatters about sqrt(scale) times less.
    """
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        good = ok & np.isfinite(own)
        spread = np.nanstd(np.where(good, own, np.nan), axis=0, ddof=1)
        mean_e = np.nanmean(np.where(good, e, np.nan), axis=0)
        return spread / math.sqrt(scale) / mean_e


def _copy_coord(ds: xr.Dataset, name: str) -> tuple:
    v = ds[name]
    return (Var(("quantity",), None, v.attrs.get("long_name", name)), v.values.astype(str))


COVERAGE_COLUMNS = (
    "setting",
    "quantity",
    "ball",
    "bat",
    "unit",
    "n_replicates",
    "n_refused",
    "bias_over_se",
    "bias_over_se_err",
    "truth_error_over_se",
    "spread_over_se",
    "spread_over_se_err",
    "coverage_68",
    "coverage_68_err",
    "coverage_95",
    "coverage_95_err",
    "mean_systematic",
    "coverage_68_combined",
    "coverage_68_combined_err",
    "coverage_95_combined",
    "coverage_95_combined_err",
    "bias_over_se_calibrated",
    "bias_over_se_calibrated_err",
    "spread_over_se_calibrated",
    "spread_over_se_calibrated_err",
    "coverage_68_calibrated",
    "coverage_68_calibrated_err",
    "coverage_95_calibrated",
    "coverage_95_calibrated_err",
    "mean_uncertainty",
    "spread",
    "mean_dof",
    "error_kind",
    "warning",
)


def _csv_text(header: Sequence[str], rows: Iterable[Sequence]) -> str:
    """Return CSV text: strings as they are, numbers as in paper_comparison.csv (empty when not finite).

    The table ends in its check line (:func:`ballbat.pipeline.checked.sealed_csv`).
    """
    import csv
    import io

    from ..compare import format_number
    from ..pipeline.checked import sealed_csv

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for row in rows:
        w.writerow([x if isinstance(x, str) else format_number(x) for x in row])
    return sealed_csv(buf.getvalue())  # its check line: a table cut short is never used


#: Columns of the coverage table in the unit of their quantity: SI in coverage.nc, the table's units in the CSV.
COVERAGE_IN_UNITS = ("mean_uncertainty", "spread", "mean_systematic")


def coverage_csv(cov: xr.Dataset) -> str:
    """Return the coverage table as CSV text (one row per sweep point and quantity).

    Values in a quantity's unit are converted from coverage.nc's SI to the unit the tables
    print (``unit``, :func:`display_unit`: rpm/deg, mph/deg as in paper_comparison.csv).
    """
    from ..units import from_si

    labels = {"quantity": "quantity_name", "ball": "ball", "bat": "bat", "error_kind": "error_kind"}
    shown = [display_unit(str(q)) for q in cov["quantity_name"].values]
    for j, (unit, si) in enumerate(zip(shown, cov["units"].values.astype(str), strict=True)):
        if unit == "1" and si != "1":
            raise ValueError(
                f"coverage: quantity {cov['quantity'].values[j]} is in {si}, but the table has no unit for it"
            )

    grid = [str(n) for n in cov["parameter"].values] if "grid_setting" in cov else []

    def row(p, j):
        for k in COVERAGE_COLUMNS:
            if k == "setting" and grid:  # a grid: its settings in words, and in columns of their own at the end
                yield " ".join(f"{n}={v:g}" for n, v in zip(grid, cov["grid_setting"].values[p], strict=True))
            elif k == "setting":
                yield cov["setting"].values[p]
            elif k == "warning":
                yield str(cov["warning"].values[p, j])
            elif k == "unit":
                yield shown[j]
            elif k in labels:
                yield str(cov[labels[k]].values[j])
            elif k in COVERAGE_IN_UNITS:
                yield from_si(float(cov[k].values[p, j]), shown[j])
            else:
                yield cov[k].values[p, j]
        if grid:
            yield from cov["grid_setting"].values[p]

    header = [*COVERAGE_COLUMNS, *grid]  # "setting,quantity,ball,bat,...": the header the guards know
    points, quantities = range(cov.sizes["point"]), range(cov.sizes["quantity"])
    return _csv_text(header, (list(row(p, j)) for p in points for j in quantities))


def run(batches: Iterable[xr.Dataset], truth: xr.Dataset) -> xr.Dataset:
    """Run the coverage stage: judge the study's batches of replicates against its truth file.

    ``batches``: the study's batch files (:func:`ballbat.studies.batch.run`); ``truth``: its truth
    (:func:`ballbat.studies.truth.run`, every sweep point). Returns :func:`coverage`'s dataset.
    """
    return coverage(combine(batches), truths_from_dataset(truth), truth_scales_from_dataset(truth))
