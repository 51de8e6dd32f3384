"""Design from a lab's own numbers (issue 37, section 4; src/ballbat/pilot.py): impacts per bat from a pilot's
measured scatter with an interval, ``ballbat design``, and one answer over a design study's sweep.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from helpers import pilot_fit as fit
from scipy import stats

from ballbat import pilot
from ballbat.studies.design import impacts_required


def test_pilot_requirement_against_a_hand_computation():
    """A standard error 0.006 from 25 impacts: s1 = 0.03 on 24 dof; n from impacts_required; chi-square interval."""
    (pooled, one) = pilot.pilot_design(fit({"A": 0.006}, {"A": 25}), delta=0.02)
    assert one.s1 == pytest.approx(0.03) and one.dof == 24
    assert one.n == impacts_required(0.03, 1.0, 0.02, 0.95, 0.8)
    lo = 0.03 * math.sqrt(24 / stats.chi2.ppf(0.975, 24))
    assert one.s1_low == pytest.approx(lo) and one.n_low == impacts_required(lo, 1.0, 0.02, 0.95, 0.8)
    assert one.n_low <= one.n <= one.n_high
    assert (pooled.n, pooled.n_low, pooled.n_high) == (one.n, one.n_low, one.n_high)  # one bat: the same
    # the requirement falls as the difference to detect grows
    assert [pilot.pilot_design(fit({"A": 0.006}, {"A": 25}), d)[1].n for d in (0.01, 0.02, 0.04)] == sorted(
        [pilot.pilot_design(fit({"A": 0.006}, {"A": 25}), d)[1].n for d in (0.01, 0.02, 0.04)], reverse=True
    )


def test_pilot_pools_the_bats_by_their_dof():
    (pooled, a, b) = pilot.pilot_design(fit({"A": 0.006, "B": 0.004}, {"A": 25, "B": 16}), delta=0.02)
    s1 = math.sqrt((24 * 0.03**2 + 15 * 0.016**2) / 39)
    assert pooled.s1 == pytest.approx(s1) and pooled.dof == 39
    assert b.n < pooled.n < a.n


def design_dataset(s1: float, sizes: list[int], replicates: int = 200, noise: float = 0.0) -> xr.Dataset:
    """A design.nc whose spread of e_x is s1 / sqrt(n) at each point, times (1 + noise_k)."""
    n = np.array(sizes, dtype=float)[:, None]
    wiggle = 1.0 + noise * np.array([1, -1] * len(sizes))[: len(sizes), None]
    sigma = s1 / np.sqrt(n) * wiggle
    return xr.Dataset(
        {
            "impacts_per_bat": (("point", "pair"), n),
            "sigma_e_x": (("point", "pair"), sigma),
            "sigma_e_x_err": (("point", "pair"), sigma / np.sqrt(2 * (replicates - 1))),
            "impacts_required": (
                ("point", "pair"),
                [[impacts_required(s, k, 0.02)] for s, k in zip(sigma[:, 0], n[:, 0], strict=True)],
            ),
        },
        coords={"ball": ("pair", ["baseball"]), "bat": ("pair", ["wood"])},
        attrs={"sweep_parameter": "impacts_per_bat", "delta_e_x": 0.02, "confidence": 0.95, "power": 0.8},
    )


def test_a_design_sweep_gives_one_answer_with_its_interval():
    """Why: the design study gave 137/157/117/135 across the sweep. The answer is one number, with an interval."""
    des = design_dataset(0.03, [10, 20, 30, 50], noise=0.08)
    per_point = des["impacts_required"].values[:, 0]
    assert not (np.all(np.diff(per_point) >= 0) or np.all(np.diff(per_point) <= 0))  # the zig-zag
    out = pilot.with_sweep_answer(des)
    n, lo, hi = (float(out[f"impacts_required_answer{s}"][0]) for s in ("", "_low", "_high"))
    assert lo <= impacts_required(0.03, 1.0, 0.02) <= hi and lo <= n <= hi
    exact = pilot.with_sweep_answer(design_dataset(0.03, [10, 20, 30, 50]))
    assert float(exact["e_x_error_per_impact"][0]) == pytest.approx(0.03, rel=1e-12)
    assert float(exact["impacts_required_answer"][0]) == impacts_required(0.03, 1.0, 0.02)
    other = design_dataset(0.03, [10, 20]).assign_attrs(sweep_parameter="pixel_noise_px")
    assert "impacts_required_answer" not in pilot.with_sweep_answer(other)  # points are other experiments
