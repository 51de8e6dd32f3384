"""A lab's bat measurements (ballbat.batlab): a pendulum period gives the same bat (issue 35)."""

from __future__ import annotations

import math

import pytest

from ballbat import batlab
from ballbat.properties import load_bats
from ballbat.units import OZ_IN2


def test_pendulum_period_gives_the_same_bat(tmp_path):
    # The period of the hickory bat about its 6-in pivot: T = 2 pi sqrt(I_p / (M g d)) (ASTM F2398).
    period = 2 * math.pi * (11200.0 / (32.0 * batlab.G_IN * 17.0)) ** 0.5  # 1.72 s
    assert batlab.moi_from_period(32.0, 23.0, 6.0, period) == pytest.approx(11200.0, rel=1e-12)
    path = tmp_path / "bats.csv"
    path.write_text(
        "bat,convention,length_in,weight_oz,balance_in,pivot_in,period_s,impact_from_knob_in,diameter_in,Iz_oz_in2\n"
        f"h,lab,34,32,23,6,{period!r},28,2.6,11\n"
    )
    assert load_bats(path)["h"].I0 / OZ_IN2 == pytest.approx(1952.0, rel=1e-9)
