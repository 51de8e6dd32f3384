"""``ballbat fly`` (ballbat.cli.fly): the calculator's case, launch conditions, many balls from a CSV (issue 13)."""

from __future__ import annotations

import csv
import json

import pytest
from helpers import ballbat_in_process as ballbat


def test_fly_reproduces_the_calculator():
    """Nathan's trajectory calculator (docs/model.md, "Flight"): 103 mph, 27.5 deg, 2500 rpm, tau 30 s
    lands at 421.5 ft after 5.52 s with apex 92.0 ft with its own fixed-step scheme.
    """
    out = ballbat("fly", "--speed", "103", "--angle", "27.5", "--backspin", "2500", "--method", "calculator", "--json")
    assert out.returncode == 0, out.stderr
    r = json.loads(out.stdout)
    assert r["carry_ft"] == pytest.approx(421.5, abs=0.05)
    assert r["hang_time_s"] == pytest.approx(5.52, abs=0.005)
    assert r["apex_ft"] == pytest.approx(92.0, abs=0.05)
    assert r["bearing_deg"] == pytest.approx(0.0, abs=1e-9)
    # the accurate integrator lands about 0.8 ft further (docs/model.md; docs/flight.md: 422.6 ft)
    acc = json.loads(ballbat("fly", "--speed", "103", "--angle", "27.5", "--backspin", "2500", "--json").stdout)
    assert 0.5 < acc["carry_ft"] - r["carry_ft"] < 1.5
    text = ballbat("fly", "--speed", "103", "--angle", "27.5", "--backspin", "2500", "--method", "calculator").stdout
    assert text.startswith("carry 421.5 ft, hang time 5.52 s, apex 92.0 ft")


def test_fly_conditions_move_the_ball():
    base = ["fly", "--speed", "100", "--angle", "28", "--backspin", "2000", "--json"]
    carry = json.loads(ballbat(*base).stdout)["carry_ft"]
    assert json.loads(ballbat(*base, "--elevation", "5280").stdout)["carry_ft"] > carry + 15  # thin air, Denver
    assert json.loads(ballbat(*base, "--wind", "0,10").stdout)["carry_ft"] > carry + 20  # tail wind
    right = json.loads(ballbat(*base, "--spray", "20").stdout)
    assert right["bearing_deg"] == pytest.approx(20, abs=1.0)


def test_fly_many_balls_from_csv(tmp_path):
    path = tmp_path / "balls.csv"
    path.write_text("speed,angle,backspin\n103,27.5,2500\n90,15,1000\n80,60,4000\n")
    out = ballbat("fly", "--csv", str(path), "--method", "calculator")
    assert out.returncode == 0, out.stderr
    rows = list(csv.DictReader(out.stdout.splitlines()))
    assert len(rows) == 3 and float(rows[0]["carry_ft"]) == pytest.approx(421.5, abs=0.05)
    assert float(rows[2]["apex_ft"]) > float(rows[1]["apex_ft"])  # the popup goes higher
    many = json.loads(ballbat("fly", "--csv", str(path), "--json").stdout)
    assert [r["speed"] for r in many] == [103.0, 90.0, 80.0]


def test_csv_with_a_bad_cell(tmp_path):
    path = tmp_path / "balls.csv"
    path.write_text("speed,angle,colour\n103,27.5,red\n")
    out = ballbat("fly", "--csv", str(path))
    assert out.returncode == 2 and "unknown column(s) colour" in out.stderr
    path.write_text("speed,angle\n103,high\n")
    out = ballbat("fly", "--csv", str(path))
    assert out.returncode == 2 and f"{path}, row 2, column angle: 'high' is not a number" in out.stderr
