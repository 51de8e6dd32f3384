"""The contact regimes of Stronge's model (ballbat.stronge.regimes): codes and boundaries against the solver."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.stronge.model import ContactParams, stronge_ex, stronge_solve
from ballbat.stronge.regimes import Regime, regime_boundaries

DEG = np.pi / 180
#: Paper, Sec. V.A: fitted eta^2 with e_y = mu = 0.5.
ETA2 = {"baseball": 4.75, "softball": 6.30}


def test_regime_codes_cover_the_solver():
    """Every label the solver gives over a wide scan has a code that reads back as the label."""
    psi = np.linspace(0.5, 89.0, 120) * DEG
    labels = set()
    for eta2 in (1.2, 2.0, 2.5, 3.5, 4.75, 10.0):
        for e_y in (0.3, 0.5, 1.0):
            labels |= set(map(str, stronge_solve(psi, ContactParams(eta2, e_y, 0.5)).regime))
    assert {"stick-slip", "slip-stick-slip", "gross-slip"} <= labels
    for label in labels:
        code = Regime.from_label(label)
        assert code.label == label or (code is Regime.LONGER_SEQUENCE and label.count("-") >= 4)
    for bad in ("slip", "stick-stick", "roll"):
        with pytest.raises(ValueError, match="not a phase sequence"):
            Regime.from_label(bad)


def test_regimes_for_fitted_eta2_no_slip_stick_slip():
    """Paper, Sec. V.A: stick-slip for tan psi < mu eta2, slip-stick-slip for
    mu eta2 <= tan psi < 3.5 mu (1 + e_y), gross slip above.

    MODEL: for Omega_t <= Omega_n (eta2 >= 3.5 on a rigid surface, i.e. both fitted balls)
    C's slip velocity can only grow during slip, so slip never turns into stick: the only
    boundary is tan psi = mu eta2 (stick-slip -> gross slip). For the baseball the paper's
    slip-stick-slip band 67.17-69.15 deg is gross slip in the model, where e_x > 0 still;
    tan psi = 3.5 mu (1 + e_y) is where e_x of gross slip crosses zero (u_f = 0): the rigid
    Coulomb-friction boundary.
    """
    for ball in ("baseball", "softball"):
        rb = regime_boundaries(ContactParams(ETA2[ball], 0.5, 0.5))
        assert rb.below == ("stick-slip",) and rb.above == ("gross-slip",)
        assert rb.psi[0] == pytest.approx(rb.psi_stick_paper, abs=1e-10)
    rb = regime_boundaries(ContactParams(4.75, 0.5, 0.5))
    assert np.rad2deg(rb.psi_stick_paper) == pytest.approx(67.166, abs=1e-3)
    assert np.rad2deg(rb.psi_gross_paper) == pytest.approx(69.146, abs=1e-3)
    band = np.linspace(rb.psi_stick_paper, rb.psi_gross_paper, 7)[1:-1]
    sol = stronge_solve(band, ContactParams(4.75, 0.5, 0.5))
    assert set(sol.regime) == {"gross-slip"}
    assert np.all(sol.e_x > 0)
    assert stronge_ex(rb.psi_rigid_reversal, ContactParams(4.75, 0.5, 0.5)) == pytest.approx(0.0, abs=1e-12)
    assert rb.psi_rigid_reversal == pytest.approx(rb.psi_gross_paper, abs=1e-12)  # rigid frame


def test_regimes_slip_stick_slip_needs_omega_t_above_omega_n():
    """MODEL: slip-stick-slip occurs only when Omega_t > Omega_n (eta2 < 3.5 on a rigid
    surface), and for e_y = 0.5 its upper end is tan psi = 3.5 mu, not the paper's
    3.5 mu (1 + e_y) (re-stick can then happen only before maximum compression).
    """
    rb = regime_boundaries(ContactParams(2.5, 0.5, 0.5))
    assert rb.below == ("stick-slip", "slip-stick-slip")
    assert rb.above == ("slip-stick-slip", "gross-slip")
    assert rb.psi[0] == pytest.approx(rb.psi_stick_paper, abs=1e-10)
    assert rb.psi[1] == pytest.approx(np.arctan(3.5 * 0.5), abs=1e-9)  # 60.26 deg
    assert np.rad2deg(rb.psi_gross_paper) == pytest.approx(69.15, abs=0.01)
    # the model's gross-slip onset in closed form, for Omega_t > Omega_n, both frames
    for args in ((2.0, 0.9, 0.3), (2.0, 1.0, 0.5), (3.0, 0.5, 0.5), (1.0, 0.7, 0.4), (2.5, 0.8, 0.5, 0.29, 0.27)):
        rb = regime_boundaries(ContactParams(*args))
        assert rb.above[-1] == "gross-slip"
        # abs 1e-8: within ~3e-9 rad below the boundary the final slip starts less than
        # SEPARATION_TOL before separation and the solver labels the impact "slip-stick"
        assert rb.psi[-1] == pytest.approx(rb.psi_gross_model, abs=1e-8)
        assert rb.psi_gross_model < rb.psi_gross_paper
    # superball: stick right up to tan psi = mu eta2, then gross slip
    rb = regime_boundaries(ContactParams(3.5, 1.0, 0.5))
    assert rb.below == ("stick",) and rb.above == ("gross-slip",)
    assert rb.psi[0] == pytest.approx(rb.psi_stick_paper, abs=1e-9)
