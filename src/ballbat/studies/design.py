"""A sweep's design: the spread of e_x per bat and the impacts per bat a lab needs (``design.nc``, ``design.csv``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy import stats

from ..pipeline.products import Var, build_dataset
from .coverage import _csv_text
from .settings import StudySettings
from .sweeps import point_dataset


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


@dataclass(frozen=True)
class Requirement:
    """Impacts per bat needed, with its interval, from a per-impact error ``s1`` known on ``dof`` dof."""

    label: str
    ball: str
    s1: float
    s1_low: float
    s1_high: float
    dof: float
    n: float
    n_low: float
    n_high: float


def requirement(label: str, ball: str, s1: float, dof: float, delta: float, settings: dict) -> Requirement:
    """Return the impacts per bat for per-impact error ``s1`` (estimated on ``dof``) and its interval.

    ``settings``: ``confidence`` and ``power`` of the test, ``level`` of the interval.
    """
    a = 1.0 - settings["level"]
    lo = s1 * math.sqrt(dof / stats.chi2.ppf(1 - a / 2, dof)) if dof > 0 else math.nan
    hi = s1 * math.sqrt(dof / stats.chi2.ppf(a / 2, dof)) if dof > 0 else math.nan

    def need(s: float) -> float:
        return impacts_required(s, 1.0, delta, settings["confidence"], settings["power"])

    return Requirement(label, ball, s1, lo, hi, dof, need(s1), need(lo), need(hi))


def sweep_answer(des: xr.Dataset, level: float = 0.95) -> list[Requirement]:
    """One requirement per pair of a design study swept over ``impacts_per_bat`` (its ``design.nc``).

    ``s1`` is the weighted mean over the sweep points of ``sigma_e_x * sqrt(impacts_per_bat)``
    (weights: the inverse squares of ``sigma_e_x_err * sqrt(impacts_per_bat)``); its interval the
    chi-square interval on the points' replicates' degrees of freedom in total, as for a pilot.
    """
    settings = {
        "confidence": float(des.attrs["confidence"]),
        "power": float(des.attrs["power"]),
        "level": level,
    }
    out = []
    for j in range(des.sizes["pair"]):
        n = des["impacts_per_bat"].values[:, j]
        s = des["sigma_e_x"].values[:, j] * np.sqrt(n)
        e = des["sigma_e_x_err"].values[:, j] * np.sqrt(n)
        ok = np.isfinite(s) & np.isfinite(e) & (e > 0)
        if not ok.any():
            continue
        w = 1.0 / e[ok] ** 2
        s1 = float(np.sum(w * s[ok]) / np.sum(w))
        # sigma_e_x_err = sigma / sqrt(2 (R - 1)): each point's dof R - 1 = (s / e)^2 / 2
        dof = float(np.sum((s[ok] / e[ok]) ** 2 / 2.0))
        label = f"{des['ball'].values[j]}:{des['bat'].values[j]}"
        out.append(requirement(label, str(des["ball"].values[j]), s1, dof, float(des.attrs["delta_e_x"]), settings))
    return out


def with_sweep_answer(des: xr.Dataset, level: float = 0.95) -> xr.Dataset:
    """Return a design study's dataset with its one answer per pair (:func:`sweep_answer`; sweeps of impacts only).

    Adds ``impacts_required_answer``, ``_low``, ``_high`` and ``e_x_error_per_impact`` (dims pair);
    a sweep of another setting is returned unchanged (its points are different experiments).
    """
    if des.attrs.get("sweep_parameter") != "impacts_per_bat":
        return des
    reqs = {r.label: r for r in sweep_answer(des, level)}
    labels = [f"{b}:{t}" for b, t in zip(des["ball"].values, des["bat"].values, strict=True)]
    pick = [reqs.get(lab) for lab in labels]

    def col(name: str) -> np.ndarray:
        return np.array([getattr(r, name) if r else np.nan for r in pick], dtype=float)

    what = f"tell two such bats delta_e_x apart: one answer over the sweep ({100 * level:g} % interval"
    out = des.copy()
    out["impacts_required_answer"] = (("pair",), col("n"), {"units": "1", "long_name": f"impacts per bat to {what})"})
    for side, name in (("low", "n_low"), ("high", "n_high")):
        out[f"impacts_required_answer_{side}"] = (
            ("pair",),
            col(name),
            {"units": "1", "long_name": f"{side} end of the interval of impacts_required_answer"},
        )
    out["e_x_error_per_impact"] = (
        ("pair",),
        col("s1"),
        {"units": "1", "long_name": "sigma_e_x * sqrt(impacts_per_bat), weighted over the sweep's points"},
    )
    return out


def run(cov: xr.Dataset, settings: StudySettings) -> xr.Dataset:
    """Run the design stage: :func:`design` of a study's coverage, with one answer over a sweep of impacts per bat.

    ``cov``: the study's coverage (:func:`ballbat.studies.coverage.run`). A sweep of
    ``impacts_per_bat`` also gets :func:`with_sweep_answer`'s one requirement per pair.
    """
    return with_sweep_answer(design(cov, settings))
