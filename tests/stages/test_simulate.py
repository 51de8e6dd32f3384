"""Sec. IV fits: e_x recovery from synthetic data, honest standard errors, line fits."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from ballbat.stages import simulate
from ballbat.synthetic import SyntheticSettings


@pytest.fixture(scope="module")
def default_settings(root):
    cfg = yaml.safe_load((root / "config" / "config.yaml").read_text())
    return cfg["datasets"]["synthetic"]["synthetic"]


def test_synthetic_is_seeded(default_settings, balls, bats):
    a = simulate.run(SyntheticSettings(**default_settings), balls, bats)
    b = simulate.run(SyntheticSettings(**default_settings), balls, bats)
    np.testing.assert_array_equal(a.omega.values, b.omega.values)
    c = simulate.run(SyntheticSettings(**{**default_settings, "seed": 1}), balls, bats)
    assert not np.array_equal(a.omega.values, c.omega.values)
    assert a.sizes["impact"] == 108 and int((a.ball == "baseball").sum()) == 58  # Table I counts
