"""Sec. V.B (ballbat.implications): the paper's D sweep shows what the paper reports; air density, launch grids."""

from __future__ import annotations

import helpers
import numpy as np
import pytest

from ballbat.implications import density_from_conditions, launch_conditions
from ballbat.units import DEGREE, FOOT, INCH, MPH, RPM

paper = helpers.paper  # a fixture of tests/helpers.py

complete = helpers.complete  # a fixture of tests/helpers.py

cfg = helpers.cfg  # a fixture of tests/helpers.py


def test_default_air_density(cfg):
    # docs/model.md, "Flight": 70 F, 15 ft, 50 %, 29.92 inHg give rho ~ 1.1938 kg/m^3.
    assert density_from_conditions(cfg["air"]) == pytest.approx(1.1938, abs=5e-4)


def test_paper_sweep_matches_sec_VB(paper):
    """Sec. V.B / Fig. 11: what the paper reports, each as a testable statement."""
    D = paper.D.values / INCH
    v = paper.exit_speed.values / MPH
    spin = paper.backspin.values / RPM
    launch = paper.launch_angle.values / DEGREE
    carry = paper.carry.values / FOOT
    # Exit speed peaks near D = 0 and drops off with D.
    assert D[np.argmax(v)] <= 0.1
    assert np.all(np.diff(v) < 0)
    # Topspin at D = 0 (the pitch's backspin).
    assert spin[0] < 0
    # Backspin roughly linear in D: a straight line explains > 99.9 % of its variance.
    r = np.corrcoef(D, spin)[0, 1]
    assert r**2 > 0.999
    # A line drive at small D, a ~400 ft home run at intermediate D, a popup at larger D.
    i = np.argmax(np.where(launch < 90, carry, -np.inf))
    assert 0.3 < D[i] < 1.2
    assert carry[i] == pytest.approx(400, abs=25)  # "a 400-ft home run"; the model gives ~393 ft
    small = np.argmin(np.abs(D - 0.25))
    assert 5 < launch[small] < 20 and carry[small] < 350  # line drive
    big = np.argmin(np.abs(D - 1.8))
    assert launch[big] > 55 and carry[big] < 200  # popup
    # The friction flag: needed |J_t/J_n| grows with D and exceeds mu = 0.5 only at large D.
    assert paper.exceeds_mu.values[0] == 0 and paper.exceeds_mu.values[-1] == 1
    assert np.all(np.diff(paper.friction_ratio.values) > 0)


def test_launch_conditions_grid_and_list(complete):
    def launch(**kw):
        return complete({"ball": "baseball", "launch": kw})["launch"]

    grid = launch_conditions(launch(exit_speed_mph=[90, 100], launch_deg=[20, 25, 30], combine="grid"))
    assert grid["exit_speed"].size == 6
    lst = launch_conditions(launch(exit_speed_mph=[90, 100], launch_deg=[20, 25], backspin_rpm=2000, combine="list"))
    np.testing.assert_allclose(lst["launch_angle"], np.radians([20, 25]))
    np.testing.assert_allclose(lst["backspin"], 2000 * RPM)
    with pytest.raises(ValueError, match=r"the lists must have one length.*exit_speed_mph has 2, launch_deg has 3"):
        launch_conditions(launch(exit_speed_mph=[90, 100], launch_deg=[20, 25, 30], combine="list"))
