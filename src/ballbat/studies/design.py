"""A sweep's design: the spread of e_x per bat and the impacts per bat a lab needs (``design.nc``, ``design.csv``)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..pipeline.products import Var, build_dataset
from .coverage import _csv_text
from .settings import StudySettings
from .sweeps import point_dataset

if TYPE_CHECKING:
    pass


def impacts_required(
    sigma: float, n_at: float, delta: float, confidence: float = 0.95, power: float = 0.8, n_max: int = 100_000
) -> float:
    """Impacts per bat needed to tell two bats ``delta`` apart in e_x.

    Two bats measured with n impacts each, e_x of each with standard deviation
    ``sigma * sqrt(n_at / n)`` (the spread found with ``n_at`` impacts, scaling as 1/sqrt(n));
    a two-sided test at ``confidence`` detects a difference ``delta`` with probability
    ``power`` when ``delta >= sqrt(2) * sigma_n * (t_{(1+c)/2} + t_{power})`` with the
    Student-t quantiles of 2 (n - 1) degrees of freedom.

    Returns
    -------
    float
        The smallest such n (at least 3), NaN when ``sigma`` is not finite, inf beyond ``n_max``.
    """
    from scipy import stats

    if not (math.isfinite(sigma) and sigma > 0 and math.isfinite(n_at) and n_at > 0):
        return math.nan
    s1 = sigma * math.sqrt(n_at)

    def enough(n: int) -> bool:
        dof = 2 * (n - 1)
        k = stats.t.ppf(0.5 + confidence / 2, dof) + stats.t.ppf(power, dof)
        return math.sqrt(2.0 / n) * s1 * k <= delta

    if not enough(n_max):
        return math.inf
    lo, hi = 2, n_max  # enough(hi) holds; find the smallest
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if enough(mid) else (mid, hi)
    return float(max(hi, 3))


DESIGN_TABLE = {
    "impacts_per_bat": Var(("point", "pair"), "1", "impacts of the ball on the bat at the sweep point"),
    "sigma_e_x": Var(("point", "pair"), "1", "standard deviation of e_x over the replicates"),
    "sigma_e_x_err": Var(("point", "pair"), "1", "standard error of sigma_e_x"),
    "mean_se_e_x": Var(("point", "pair"), "1", "mean reported standard error of e_x"),
    "impacts_required": Var(
        ("point", "pair"), "1", "impacts per bat to tell two such bats delta_e_x apart (confidence, power)"
    ),
    "setting": Var(("point",), "1", "value of the swept setting"),
}


def design(cov: xr.Dataset, settings: StudySettings) -> xr.Dataset:
    """Spread of e_x per bat and ball at each sweep point and the impacts a lab would need.

    Parameters
    ----------
    cov : xarray.Dataset
        :func:`coverage` of the study.
    settings : StudySettings
        Its sweep, and the difference in e_x between two bats to detect (``delta_e_x``) with
        the ``confidence`` and ``power`` of the two-sided test.

    Returns
    -------
    xarray.Dataset
        Dims point x pair (a pair is one ball on one bat).
    """
    sel = np.flatnonzero(cov["quantity_name"].values == "e_x")
    balls = cov["ball"].values[sel].astype(str)
    bats = cov["bat"].values[sel].astype(str)
    npt = cov.sizes["point"]
    out = {k: np.full((npt, sel.size), np.nan) for k in DESIGN_TABLE if k != "setting"}
    for p in range(npt):
        ds = point_dataset(settings.dataset, settings.parameter, settings.values[p])
        for j, q in enumerate(sel):
            n_at = float(ds["synthetic"]["impacts"][balls[j]][bats[j]])
            sigma = float(cov["spread"].values[p, q])
            n = float(cov["n_replicates"].values[p, q])
            out["impacts_per_bat"][p, j] = n_at
            out["sigma_e_x"][p, j] = sigma
            out["sigma_e_x_err"][p, j] = sigma / math.sqrt(2 * max(n - 1, 1))
            out["mean_se_e_x"][p, j] = float(cov["mean_uncertainty"].values[p, q])
            out["impacts_required"][p, j] = impacts_required(
                sigma, n_at, settings.delta_e_x, settings.confidence, settings.power
            )
    out["setting"] = cov["setting"].values
    coords = {
        "point": (Var(("point",), "1", "sweep point"), np.arange(npt, dtype=np.int64)),
        "pair": (Var(("pair",), None, "ball:bat"), np.array([f"{b}:{t}" for b, t in zip(balls, bats, strict=True)])),
        "ball": (Var(("pair",), None, "ball type"), balls),
        "bat": (Var(("pair",), None, "bat"), bats),
    }
    attrs = {
        "sweep_parameter": settings.parameter or "",
        "delta_e_x": settings.delta_e_x,
        "confidence": settings.confidence,
        "power": settings.power,
    }
    return build_dataset(DESIGN_TABLE, out, coords, attrs)


DESIGN_COLUMNS = (
    "parameter",
    "setting",
    "ball",
    "bat",
    "impacts_per_bat",
    "sigma_e_x",
    "sigma_e_x_err",
    "mean_se_e_x",
    "impacts_required",
)


def design_csv(des: xr.Dataset) -> str:
    """Return the design table as CSV text (one row per sweep point, ball and bat)."""

    def row(p, j):
        head = [des.attrs["sweep_parameter"], des["setting"].values[p], str(des["ball"].values[j])]
        return head + [str(des["bat"].values[j])] + [des[k].values[p, j] for k in DESIGN_COLUMNS[4:]]

    return _csv_text(DESIGN_COLUMNS, (row(p, j) for p in range(des.sizes["point"]) for j in range(des.sizes["pair"])))
