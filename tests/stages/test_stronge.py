"""The Stronge stage (ballbat.stages.stronge): a ball with too few usable impacts is reported, not fitted."""

from __future__ import annotations

import numpy as np
from helpers import FIT, NORM, REC

from ballbat.stages import fit_ex, normalize, reconstruct, simulate, stronge
from ballbat.synthetic import SyntheticSettings


def test_ball_with_too_few_usable_impacts_is_reported_not_fitted(default_settings, config, balls, bats):
    """A ball with 2 usable impacts: every per-ball result NaN with n = 2, no warnings, no crash."""
    settings = {**default_settings, "impacts": {"baseball": {"wood": 12}, "softball": {"wood": 2}}}
    rec = reconstruct.run(
        REC, normalize.run(NORM, simulate.run(SyntheticSettings(**settings), balls, bats)), balls, bats
    )
    fit = fit_ex.run(FIT, rec)
    soft = fit.sel(ball="softball")
    assert int(soft.e_x_pooled_n) == 2 and np.isnan(soft.e_x_pooled)
    for q in ("tan_ratio_slope", "spin_theta_slope", "e_y_implied", "mu_k_lower_bound"):
        assert np.isnan(soft[q]), q
    assert np.isfinite(fit.e_x_pooled.sel(ball="baseball"))
    st = stronge.run(stronge.StrongeSettings(**{**config["stronge"], "n_time": 50}), rec)
    assert list(st.ball.values) == ["baseball"]
    assert "softball: 2 usable impacts" in st.attrs["balls_not_fitted"]
