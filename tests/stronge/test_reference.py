"""Stronge's model against its reference implementation (ballbat.stronge.reference): closed forms, event times."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.stronge.model import ContactParams, stronge_ex, stronge_solve
from ballbat.stronge.reference import stronge_reference

DEG = np.pi / 180


def _sample(rng, n, frame):
    psi = rng.uniform(0, 85, n) * DEG
    eta2 = rng.uniform(2, 10, n)
    e_y = rng.uniform(0.3, 1, n)
    mu = rng.uniform(0.1, 1, n)
    if frame == "rigid":
        r_x = r_y = np.zeros(n)
    else:  # the range spanned by Tables I-II (r_x 0.20-0.41, r_y 0.22-0.38)
        r_x, r_y = rng.uniform(0.15, 0.45, n), rng.uniform(0.15, 0.45, n)
    # edges of the domain: psi = 0 and 85 deg, eta2 = 2 and 10, e_y = 0.3 and 1, mu = 0.1 and 1
    edges = np.array(np.meshgrid([0.0, 85 * DEG], [2.0, 10.0], [0.3, 1.0], [0.1, 1.0])).reshape(4, -1)
    k = edges.shape[1]
    r_edge = (np.zeros(k), np.zeros(k)) if frame == "rigid" else (np.full(k, 0.29), np.full(k, 0.27))
    cat = np.concatenate
    contact = ContactParams(
        cat([eta2, edges[1]]), cat([e_y, edges[2]]), cat([mu, edges[3]]), cat([r_x, r_edge[0]]), cat([r_y, r_edge[1]])
    )
    return cat([psi, edges[0]]), contact


# ------------------------------------------------------------------------------------------
# closed form vs numerical integration
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("frame", ["rigid", "bat"])
def test_closed_form_matches_reference(frame):
    """|e_x(closed form) - e_x(solve_ivp, rtol 1e-12)| < 1e-8 over the whole test domain."""
    args = _sample(np.random.default_rng(2017 if frame == "rigid" else 503), 200, frame)
    ref = stronge_reference(*args)
    fast = stronge_ex(*args)
    sol = stronge_solve(*args)
    np.testing.assert_allclose(fast, ref["e_x"], rtol=0, atol=1e-8)
    np.testing.assert_allclose(sol.e_x, ref["e_x"], rtol=0, atol=1e-8)
    assert np.array_equal(sol.regime, ref["regime"])


def test_reference_event_times_match():
    """Phase-change times of the closed form agree with the integrator's events."""
    psi = np.array([30.0, 60.0, 75.0]) * DEG
    sol = stronge_solve(psi, ContactParams(2.5, 0.5, 0.5))
    ref = stronge_reference(psi, ContactParams(2.5, 0.5, 0.5))
    assert list(sol.regime) == ["stick-slip", "slip-stick-slip", "gross-slip"]
    assert sol.t_stick_end[0] == pytest.approx(ref["events"][0][0][0], abs=1e-9)
    assert sol.t_restick[1] == pytest.approx(ref["events"][1][0][0], abs=1e-9)
    assert sol.t_final_slip[1] == pytest.approx(ref["events"][1][1][0], abs=1e-9)
    assert ref["t_c"][0] == pytest.approx(np.pi / 2, abs=1e-10)
