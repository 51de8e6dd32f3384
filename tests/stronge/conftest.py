"""Fixtures shared by the test modules of this folder."""

import numpy as np
import pytest

from ballbat.properties import recoil_factors
from ballbat.stronge.analysis import VtfData, VtfNoise
from ballbat.stronge.model import ContactParams, stronge_ex


@pytest.fixture(scope="module")
def data() -> VtfData:
    """Thirty impacts on three bats, with noise on four measured values."""
    rng = np.random.default_rng(39)
    n = 30
    psi = rng.uniform(0.02, 0.7, n)
    r_x, r_y = rng.uniform(0.1, 0.4, n), rng.uniform(0.05, 0.3, n)
    x = np.tan(psi) / (1.0 + r_x)
    ex = stronge_ex(psi, ContactParams(5.0, 0.5, 0.5, r_x, r_y, 0.4))
    y = (1.0 + ex) * x + rng.normal(0.0, 0.01, n)
    noise = VtfNoise(rng.normal(0.0, 0.3, (n, 4)), rng.normal(0.0, 0.3, (n, 4)), rng.uniform(0.005, 0.02, (n, 4)))
    bat = np.repeat(["a", "b", "c"], n // 3)
    return VtfData(psi, x, y, rng.uniform(0.005, 0.02, n), r_x, r_y, np.full(n, 0.4), bat, noise)


@pytest.fixture(scope="module")
def wood(balls, bats):
    """(r_x, r_y) of each ball on the wood bat (Tables I and II)."""
    return {b: recoil_factors(balls[b], bats["wood"]) for b in ("baseball", "softball")}
