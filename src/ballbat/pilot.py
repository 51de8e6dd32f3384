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

:func:`~ballbat.studies.design.sweep_answer` does the same for a design study's sweep of impacts per bat: one ``s1`` per
bat and ball fitted over every sweep point (the spread of e_x times sqrt(n), weighted by its
standard error), so the study gives one number with its interval instead of one noisy number per
point.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .studies.design import Requirement, requirement, sweep_answer, with_sweep_answer

__all__ = ["Requirement", "pilot_design", "requirement", "requirement_lines", "sweep_answer", "with_sweep_answer"]

if TYPE_CHECKING:
    import xarray as xr


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
