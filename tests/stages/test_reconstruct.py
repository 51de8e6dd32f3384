"""The reconstruct stage (ballbat.stages.reconstruct): implied e_y exact for bats of different e_x (Sec. IV)."""

from __future__ import annotations

import pytest
from helpers import NORM, REC
from helpers import fit_chain as run

from ballbat.stages import normalize, reconstruct, simulate
from ballbat.synthetic import SyntheticSettings


def test_implied_e_y_is_exact_for_bats_of_different_e_x(default_settings, balls, bats):
    """Eq. ratio inverted impact by impact: noise-free impacts on bats of different e_x give e_y back.

    The inversion with the pooled e_x and the mean recoil factors misses by more than the
    error once the fit weighs the bats differently (the replicate studies found a bias of
    0.3-0.6 standard errors); weighting each impact's c_i (1 + e_x of its bat) as the fit does
    is exact.
    """
    from ballbat.kinematics import e_y_from_tan_ratio_slope

    tiny = {k: 1e-4 for k in default_settings["noise"]}
    fit = run(default_settings, balls, bats, noise=tiny, impacts={"baseball": {"wood": 60, "metal_rough": 10}})
    f = fit.sel(ball="baseball")
    assert float(f.e_y_implied) == pytest.approx(0.45, abs=1e-4)
    rec = reconstruct.run(
        REC,
        normalize.run(
            NORM,
            simulate.run(
                SyntheticSettings(
                    **{**default_settings, "noise": tiny, "impacts": {"baseball": {"wood": 60, "metal_rough": 10}}}
                ),
                balls,
                bats,
            ),
        ),
        balls,
        bats,
    )
    naive = e_y_from_tan_ratio_slope(
        float(f.tan_ratio_slope), float(f.e_x_pooled), *(float(rec[k].mean()) for k in ("r_x", "r_y", "alpha"))
    )
    assert abs(naive - 0.45) > 10 * abs(float(f.e_y_implied) - 0.45)
