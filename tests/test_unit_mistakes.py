"""Unit mistakes in a few rows are named as such, even in one row (issue 35, item 5).

Before, a row of spin in rad/s in an rpm file was excluded only as "implausible" (no hint of
units), and such a row at small psi was kept and fitted with "0 warning(s)". Now an excluded
row whose values fit another unit says which, and a kept row that fits another unit far better
is a warning naming its line, its column and the unit.
"""

from __future__ import annotations

import math

import pytest
from conftest import ROOT

from ballbat.kinematics import ImpactFlag
from ballbat.stages import ingest as ingest_stage

MAPLE = ROOT / "config" / "examples" / "maple_impacts.csv"
BALLS = ROOT / "config" / "balls.csv"
MAPLE_BATS = ROOT / "config" / "examples" / "maple_bats.csv"
RPM_PER_RAD_S = 2 * math.pi / 60


def rewritten(tmp_path, column, factor, rows, keep_err=True):
    """The maple example (without its glitch row) with ``column`` (and its ``_err``) times ``factor`` in ``rows``."""
    lines = [line.split(",") for line in MAPLE.read_text().splitlines()][:31]
    if not keep_err:
        lines = [line[:7] for line in lines]
    head = lines[0]
    for i in rows:
        for c in (column, f"{column}_err"):
            if c in head:
                lines[i + 1][head.index(c)] = f"{float(lines[i + 1][head.index(c)]) * factor:.5g}"
    path = tmp_path / "impacts.csv"
    path.write_text("\n".join(",".join(r) for r in lines) + "\n")
    return path


def ingested(path):
    ds = ingest_stage.run(ingest_stage.IngestSettings(calibration={}), path, BALLS, MAPLE_BATS)
    return ds, ingest_stage.warnings(ds)


@pytest.mark.parametrize(
    ("column", "factor", "unit"),
    [
        ("omega_rpm", RPM_PER_RAD_S, "spin in rad/s, not rpm"),
        ("omega_rpm", 1 / 60, "spin in rev/s, not rpm"),
        ("v_ball_mph", 1.609344, "exit speed in km/h, not mph"),
        ("v_bat_mph", 0.44704, "bat speed in m/s, not mph"),
        ("theta_deg", math.pi / 180, "angle in radians, not degrees"),
    ],
)
@pytest.mark.parametrize("row", [0, 5, 12])
def test_one_row_in_another_unit_is_excluded_naming_the_unit(tmp_path, column, factor, unit, row):
    ds, _ = ingested(rewritten(tmp_path, column, factor, [row]))
    assert ds.ingest_flag.values[row] == ImpactFlag.IMPLAUSIBLE
    reason = str(ds.ingest_flag_reason.values[row])
    assert reason.startswith("implausible: ") and f"likely a unit mistake: column {column}" in reason
    assert f"the row fits {unit} far better" in reason
    assert (ds.ingest_flag.values != 0).sum() == 1  # no other row


def test_every_row_of_a_mixed_file_names_the_unit(tmp_path):
    """12 of 30 rows with spin in rad/s: each excluded row names rad/s."""
    ds, _ = ingested(rewritten(tmp_path, "omega_rpm", RPM_PER_RAD_S, range(12)))
    bad = ds.ingest_flag.values == ImpactFlag.IMPLAUSIBLE
    assert bad.sum() >= 10
    assert all("spin in rad/s, not rpm far better" in str(r) for r in ds.ingest_flag_reason.values[bad])


def test_a_kept_row_that_fits_another_unit_is_a_warning(tmp_path):
    """Without uncertainty columns, a rad/s row at small psi is not excluded (it is within the
    file's spread): it was fitted with 0 warnings; now it is named with its line and the unit.
    """
    ds, warnings = ingested(rewritten(tmp_path, "omega_rpm", RPM_PER_RAD_S, [3], keep_err=False))
    assert ds.ingest_flag.values[3] == 0
    named = [w for w in warnings if ": row 5: column omega_rpm: the row fits spin in rad/s, not rpm far better" in w]
    assert len(named) == 1 and "a unit mistake in this row?" in named[0]


def test_clean_files_name_no_unit_mistake():
    for path, bats in ((MAPLE, MAPLE_BATS), (ROOT / "config" / "examples" / "hickory_impacts.csv", None)):
        bats = bats or ROOT / "config" / "examples" / "hickory_bats.csv"
        ds = ingest_stage.run(ingest_stage.IngestSettings(calibration={}), path, BALLS, bats)
        assert not any("unit mistake" in w for w in ingest_stage.warnings(ds))
        assert not any("unit mistake" in str(r) for r in ds.ingest_flag_reason.values)
