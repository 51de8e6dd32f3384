"""The design study (ballbat.studies.design): the impacts per bat needed to tell two bats apart."""

from __future__ import annotations

import math

from scipy import stats

from ballbat.studies.design import impacts_required


def test_impacts_required_matches_the_normal_formula_for_many_impacts():
    # sigma with n_at impacts -> single-impact sigma s1; large n: n = 2 (z_a + z_b)^2 s1^2 / delta^2
    s1, delta = 0.1, 0.02
    n_normal = 2 * (stats.norm.ppf(0.975) + stats.norm.ppf(0.8)) ** 2 * s1**2 / delta**2
    n = impacts_required(s1 / math.sqrt(20), 20, delta)
    assert n_normal < n < n_normal * 1.03  # t quantiles: a little more than the normal answer
    assert impacts_required(s1 / math.sqrt(20), 20, 2 * delta) < n
    assert impacts_required(1e-6, 20, delta) == 3
    assert math.isnan(impacts_required(math.nan, 20, delta))
    assert impacts_required(1.0, 20, 1e-6) == math.inf
