"""Design from a lab's own numbers: impacts per bat to tell two bats apart, from measured scatter (issue 37).

A pilot session (a dataset's ``fit_ex.nc``) gives each bat's e_x with its standard error ``se``
from ``n0`` impacts; the error of one impact is ``s1 = se sqrt(n0)`` (the intrinsic scatter of e_x
is in ``se``: the random-effects fit). With n impacts per bat, e_x of each bat has error
``s1 / sqrt(n)``, and :func:`ballbat.studies.design.impacts_required` gives the smallest n at which a
two-sided test at ``confidence`` finds two bats ``delta`` apart with probability ``power``. The
interval: ``s1`` is estimated on ``n0 - 1`` degrees of freedom, so its ``level`` interval is
``s1 sqrt(dof / chi2_{(1 +- level)/2, dof})``, and n is monotone in s1. Per ball, the bats'
``s1`` are pooled (variances weighted by their degrees of freedom) into the lab's one answer.

The design is for bats compared within a test session, where a shared calibration systematic
cancels (docs/league.md); bats compared across sessions also carry the systematic, which more
impacts do not reduce.

:func:`sweep_answer` does the same for a design study's sweep of impacts per bat: one ``s1`` per
bat and ball fitted over every sweep point (the spread of e_x times sqrt(n), weighted by its
standard error), so the study gives one number with its interval instead of one noisy number per
point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy import stats

from .studies.design import impacts_required

if TYPE_CHECKING:
    import xarray as xr


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


def pilot_design(
    fit: xr.Dataset, delta: float, confidence: float = 0.95, power: float = 0.8, level: float = 0.95
) -> list[Requirement]:
    """Return per ball the pooled requirement, then each bat's, from a pilot's fit_ex.nc.

    Raises ValueError when no bat of the file has an e_x with its error from two or more impacts.
    """
    settings = {"confidence": confidence, "power": power, "level": level}
    out = []
    for ball in (str(b) for b in fit["ball"].values):
        bats = []
        for bat in (str(t) for t in fit["bat"].values):
            sel = {"ball": ball, "bat": bat}
            se, n0 = float(fit["e_x_err"].sel(**sel)), int(fit["e_x_n"].sel(**sel))
            if np.isfinite(se) and se > 0 and n0 >= 2:
                bats.append(requirement(bat, ball, se * math.sqrt(n0), n0 - 1, delta, settings))
        if not bats:
            continue
        dof = sum(b.dof for b in bats)
        s1 = math.sqrt(sum(b.dof * b.s1**2 for b in bats) / dof)
        out.append(requirement(f"pooled over {len(bats)} bat(s)", ball, s1, dof, delta, settings))
        out += bats
    if not out:
        raise ValueError("no bat has an e_x with a standard error from two or more impacts")
    return out


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


def requirement_lines(reqs: list[Requirement], delta: float, confidence: float, power: float) -> list[str]:
    """Return the requirements in words, one line each."""
    out = [
        f"Impacts per bat to tell two bats {delta:g} apart in e_x (two-sided {100 * confidence:g} %, "
        f"power {100 * power:g} %), with the 95 % interval from the measured scatter:"
    ]
    for r in reqs:
        pooled = r.label.startswith("pooled")
        head = f"{r.ball}, {r.label}" if pooled else f"  {r.label}"
        out.append(
            f"{head}: {_n(r.n)} (95 %: {_n(r.n_low)} to {_n(r.n_high)}); per-impact error of e_x {r.s1:.4f} "
            f"({r.s1_low:.4f} to {r.s1_high:.4f}, {r.dof:g} dof)"
        )
    return out


def _n(v: float) -> str:
    return "more than 100000" if math.isinf(v) else ("--" if math.isnan(v) else f"{v:.0f}")


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
