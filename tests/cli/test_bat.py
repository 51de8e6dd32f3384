"""``ballbat bat`` through the installed entry point: a lab's measurements as a bat-table row (issue 35)."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers import ballbat_forked as ballbat

from ballbat.properties import load_balls, recoil_factors
from ballbat.units import INCH, OUNCE, OZ_IN2

ROOT = Path(__file__).resolve().parents[2]
HICKORY = "--length 34 --weight 32 --balance-point 23.0 --moi-6in 11200 --impact-from-tip 6 --diameter 2.6 --iz 11"


def test_bat_prints_the_paper_row_and_the_centre_of_percussion():
    got = ballbat("bat", *HICKORY.split(), "--name", "hickory", installed=True)
    assert got.returncode == 0, got.stderr
    lines = got.stdout.splitlines()
    # I0 = 11200 - 32 (23 - 6)^2 = 1952; b = 34 - 6 - 23 = 5; R = 1.3 (parallel-axis theorem)
    assert lines[1:3] == ["bat,name,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in", "hickory,hickory,32,1952,11,5,1.3"]
    assert "26.59 in from the knob" in got.stdout  # 6 + 11200 / (32 * 17)
    assert "convention" in lines[4] and lines[5].startswith("hickory,hickory,lab,34,32,23,6")


@pytest.mark.slow  # more than 2 s
def test_bat_period_and_pivot_give_the_same_row():
    period = 2 * 3.141592653589793 * (11200.0 / (32.0 * 9.80665 / INCH * 17.0)) ** 0.5
    args = "--length 34 --weight 32 --balance-point 23 --pivot 6 --impact-from-knob 28 --diameter 2.6 --iz 11"
    got = ballbat("bat", *args.split(), "--period", repr(period))
    assert got.returncode == 0, got.stderr
    assert "mybat,mybat,32,1952,11,5,1.3" in got.stdout


def test_bat_uncertainty_of_each_value_moves_e_x_as_the_fit_would():
    got = ballbat("bat", *HICKORY.split(), "--iz-err", "0.1", "--e-x", "0.455")
    iz_line = next(line for line in got.stdout.splitlines() if line.strip().startswith("Iz_oz_in2"))
    # (1 + e_x) scales as (1 + r_x) at fixed data (Eq. omega): Iz +- 10 %
    ball = load_balls(ROOT / "config" / "balls.csv")["baseball"]
    from ballbat.properties import Bat

    r_x = [
        recoil_factors(ball, Bat("h", "h", 32 * OUNCE, 1952 * OZ_IN2, iz * OZ_IN2, 5 * INCH, 1.3 * INCH))[0]
        for iz in (11.0, 12.1, 9.9)
    ]
    want = 1.455 * abs(r_x[1] - r_x[2]) / 2 / (1 + r_x[0])
    assert float(iz_line.split("+-")[-1]) == pytest.approx(want, abs=6e-5)
    assert "all, in quadrature" in got.stdout


def test_bat_refuses_a_bat_no_lab_measures_with_the_likely_mistake():
    got = ballbat("bat", *HICKORY.replace("--weight 32", "--weight 907").split())
    assert got.returncode == 1
    assert "grams typed as ounces" in got.stdout and "not a bat row" in got.stderr


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (HICKORY.replace(" --iz 11", ""), "argument --iz: required"),
        (HICKORY + " --period 1.7", "give one of --moi"),
        (HICKORY + " --ball cricket", "argument --ball: 'cricket'"),
    ],
)
def test_bat_bad_arguments_are_one_line(args, words):
    got = ballbat("bat", *args.split())
    assert got.returncode == 2 and words in got.stderr and len(got.stderr.splitlines()) == 1
