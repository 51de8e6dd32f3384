"""The simulate stage (ballbat.stages.simulate): synthetic impacts are seeded."""

from __future__ import annotations

import numpy as np

from ballbat.stages import simulate
from ballbat.synthetic import SyntheticSettings


def test_synthetic_is_seeded(default_settings, balls, bats):
    a = simulate.run(SyntheticSettings(**default_settings), balls, bats)
    b = simulate.run(SyntheticSettings(**default_settings), balls, bats)
    np.testing.assert_array_equal(a.omega.values, b.omega.values)
    c = simulate.run(SyntheticSettings(**{**default_settings, "seed": 1}), balls, bats)
    assert not np.array_equal(a.omega.values, c.omega.values)
    assert a.sizes["impact"] == 108 and int((a.ball == "baseball").sum()) == 58  # Table I counts
