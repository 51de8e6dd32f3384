"""Per-row plausibility of measured impacts and the physical range of fitted e_x (issue 10, item 1).

A unit mistake must not give a number that looks right. The maple example (31 impacts, true
e_x = 0.42) is rewritten with the mistakes labs make; each is caught as an error of the dataset
or, row by row, as excluded impacts kept with their reason. On clean synthetic experiments no
impact is flagged.
"""

import csv
import math

import numpy as np
import pytest
from conftest import ROOT

from ballbat.fitting import ImplausibleFit
from ballbat.kinematics import ImpactFlag
from ballbat.properties import InputError, load_balls, load_bats
from ballbat.stages import fit_ex, normalize, reconstruct, simulate
from ballbat.stages import ingest as ingest_stage
from ballbat.synthetic import SyntheticSettings
from ballbat.units import DEGREE, MPH, RPM

MAPLE = ROOT / "config" / "examples" / "maple_impacts.csv"
BALLS = ROOT / "config" / "balls.csv"
MAPLE_BATS = ROOT / "config" / "examples" / "maple_bats.csv"
RPM_PER_RAD_S = 2 * math.pi / 60


def ingest(path, balls, bats):
    """The ingest stage's file of ``path`` and its warnings."""
    ds = ingest_stage.run(ingest_stage.IngestSettings(calibration={}), path, balls, bats)
    return ds, ingest_stage.warnings(ds)


def rewritten(tmp_path, columns, factor, rows=lambda i: True):
    """Write the maple example with ``columns`` multiplied by ``factor`` in the selected rows."""
    lines = [line.split(",") for line in MAPLE.read_text().splitlines()]
    head = lines[0]
    for i, row in enumerate(lines[1:]):
        if rows(i):
            for c in columns:
                j = head.index(c)
                row[j] = f"{float(row[j]) * factor:.5g}"
    path = tmp_path / "impacts.csv"
    path.write_text("\n".join(",".join(r) for r in lines) + "\n")
    return path


def fitted(path):
    ds, _ = ingest(path, BALLS, MAPLE_BATS)
    rec = reconstruct.run(
        reconstruct.ReconstructSettings(),
        normalize.run(normalize.NormalizeSettings(v_ref_mph=77.0), ds),
        load_balls(BALLS),
        load_bats(MAPLE_BATS),
    )
    return ds, fit_ex.run(fit_ex.FitExSettings(mu_k_example=0.5, systematic=True, check_physical=True), rec)


def test_clean_file_flags_nothing():
    ds, fit = fitted(MAPLE)
    assert not (ds.ingest_flag.values == ImpactFlag.IMPLAUSIBLE).any()
    assert float(fit.e_x_pooled.sel(ball="baseball")) == pytest.approx(0.42, abs=0.03)


@pytest.mark.parametrize(
    ("columns", "factor", "what"),
    [
        (["v_bat_mph", "v_ball_mph", "v_bat_mph_err", "v_ball_mph_err"], MPH, "speeds in m/s"),  # gave e_x = 1.39
        (["v_bat_mph", "v_ball_mph", "v_bat_mph_err", "v_ball_mph_err"], 1.609344, "speeds in km/h"),  # gave 0.50
        (["omega_rpm", "omega_rpm_err"], RPM_PER_RAD_S, "spin in rad/s"),  # gave e_x = -0.74
    ],
)
def test_unit_mistakes_stop_the_dataset(tmp_path, columns, factor, what):
    with pytest.raises(InputError) as err:
        ingest(rewritten(tmp_path, columns, factor), BALLS, MAPLE_BATS)
    first = err.value.problems[0]
    assert "impacts are measurements no ball-bat collision can produce, more than half" in first, what
    assert "units are likely wrong" in first
    assert any("row " in p for p in err.value.problems[1:]), "the rows are named"


def test_reversed_spin_is_an_error_not_a_note(tmp_path):
    """The spin's sign reversed gave e_x = -4.17 with status ok; now the fit refuses it."""
    with pytest.raises(ImplausibleFit, match=r"fitted e_x outside the physical range \[-1, 1\].*spin sign"):
        fitted(rewritten(tmp_path, ["omega_rpm"], -1.0))


def test_mixed_units_are_caught_row_by_row(tmp_path):
    """12 of 31 rows with spin in rad/s (gave e_x = -0.37 +- 0.11 with no warning).

    With the file's stated uncertainties every such row is excluded by name, no row in the right
    unit is, and the fit of the rest recovers the true e_x = 0.42.
    """
    bad_rows = set(range(12))
    path = rewritten(tmp_path, ["omega_rpm", "omega_rpm_err"], RPM_PER_RAD_S, lambda i: i in bad_rows)
    ds, fit = fitted(path)
    flagged = set(np.flatnonzero(ds.ingest_flag.values == ImpactFlag.IMPLAUSIBLE))
    assert flagged == bad_rows
    assert all(r.startswith("implausible: ") for r in ds.ingest_flag_reason.values[sorted(flagged)])
    e_x, err = float(fit.e_x_pooled.sel(ball="baseball")), float(fit.e_x_pooled_err.sel(ball="baseball"))
    assert abs(e_x - 0.42) < 2 * err


def test_mixed_units_without_uncertainties(tmp_path):
    """Without uncertainty columns the file's robust spread judges: the rows whose mistake stands
    above the noise (psi >= 10 deg) are excluded, and no row in the right unit is.
    """
    lines = [line.split(",")[:7] for line in MAPLE.read_text().splitlines()]  # drop the *_err columns
    j = lines[0].index("omega_rpm")
    for row in lines[1:13]:
        row[j] = f"{float(row[j]) * RPM_PER_RAD_S:.5g}"
    path = tmp_path / "noerr.csv"
    path.write_text("\n".join(",".join(r) for r in lines) + "\n")
    ds, _ = ingest(path, BALLS, MAPLE_BATS)
    flagged = set(np.flatnonzero(ds.ingest_flag.values == ImpactFlag.IMPLAUSIBLE))
    assert flagged <= set(range(12)) and len(flagged) >= 6


def test_no_false_alarms_on_clean_synthetic_experiments(tmp_path, config, balls, bats):
    """10 draws of the paper-sized experiment (1080 impacts) written as lab files: nothing flagged."""
    flagged = 0
    for seed in range(10):
        s = SyntheticSettings(**{**config["datasets"]["synthetic"]["synthetic"], "seed": seed})
        ds = simulate.run(s, balls, bats)
        path = tmp_path / f"s{seed}.csv"
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["bat", "ball", "v_bat_mph", "v_ball_mph", "theta_deg", "omega_rpm"])
            for i in range(ds.sizes["impact"]):
                w.writerow(
                    [
                        ds.bat.values[i],
                        ds.ball.values[i],
                        ds.v_bat.values[i] / MPH,
                        ds.v_ball.values[i] / MPH,
                        ds.theta.values[i] / DEGREE,
                        ds.omega.values[i] / RPM,
                    ]
                )
        out, _ = ingest(path, BALLS, ROOT / "config" / "bats.csv")
        flagged += int((out.ingest_flag.values == ImpactFlag.IMPLAUSIBLE).sum())
    assert flagged == 0


def test_rows_pasted_twice_are_an_error(tmp_path):
    """The same rows twice without impact_id (accepted before, shrinking the errors by sqrt 2)."""
    lines = [",".join(line.split(",")[1:]) for line in MAPLE.read_text().splitlines()]  # no impact_id
    path = tmp_path / "twice.csv"
    path.write_text("\n".join([*lines, *lines[1:4]]) + "\n")
    with pytest.raises(InputError) as err:
        ingest(path, BALLS, MAPLE_BATS)
    dup = [p for p in err.value.problems if "the same measurement as" in p]
    assert len(dup) == 3
    assert dup[0].startswith(f"{path}: row 33: the same measurement as row 2")


def test_netcdf_uncertainty_units_are_checked(tmp_path):
    """omega_rpm_err in rad/s in a NetCDF file was accepted; it is named now."""
    import xarray as xr

    rows = [line.split(",") for line in MAPLE.read_text().splitlines()]
    head, body = rows[0], rows[1:]
    data = {}
    for j, name in enumerate(head):
        values = [r[j] for r in body]
        unit = name.rsplit("_", 2)[-2] if name.endswith("_err") else name.rsplit("_", 1)[-1]
        if name in ("impact_id", "bat", "ball"):
            data[name] = ("impact", values)
        else:
            data[name] = ("impact", np.asarray(values, dtype=float), {"units": unit})
    data["omega_rpm_err"][2]["units"] = "rad s-1"
    path = tmp_path / "impacts.nc"
    xr.Dataset(data).to_netcdf(path)
    with pytest.raises(InputError) as err:
        ingest(path, BALLS, MAPLE_BATS)
    assert err.value.problems == [f"{path}: variable omega_rpm_err: units 'rad s-1', expected 'rpm'"]


# ---------------------------------------------------------------------------------------
# CSV files as labs make them (issue 10, item 12)


def _maple_values(path):
    ds, _ = ingest(path, BALLS, MAPLE_BATS)
    return ds


def test_excel_utf8_bom_is_read(tmp_path):
    path = tmp_path / "bom.csv"
    path.write_bytes(b"\xef\xbb\xbf" + MAPLE.read_bytes())
    np.testing.assert_array_equal(_maple_values(path).v_bat.values, _maple_values(MAPLE).v_bat.values)


def test_semicolons_and_decimal_commas_are_read(tmp_path):
    """European Excel: ';' between cells and ',' as the decimal mark; read as the same numbers."""
    text = MAPLE.read_text().replace(",", ";").replace(".", ",")
    path = tmp_path / "eu.csv"
    path.write_text(text)
    eu, ref = _maple_values(path), _maple_values(MAPLE)
    for v in ("v_bat", "v_ball", "theta", "omega", "omega_err"):
        np.testing.assert_array_equal(eu[v].values, ref[v].values)


def test_latin1_file_is_named_not_utf8(tmp_path):
    path = tmp_path / "latin1.csv"
    text = MAPLE.read_text().replace("maple", "érable", 1)
    path.write_bytes(text.encode("latin-1"))
    with pytest.raises(InputError) as err:
        ingest(path, BALLS, MAPLE_BATS)
    assert err.value.problems == [
        f"{path}: not UTF-8 text: byte 0xe9 on line 2 cannot be decoded (a Latin-1 or Windows export?); "
        "save the file as 'CSV UTF-8'"
    ]


def test_trailing_empty_columns_are_ignored(tmp_path):
    path = tmp_path / "trailing.csv"
    path.write_text("\n".join(line + ",," for line in MAPLE.read_text().splitlines()) + "\n")
    np.testing.assert_array_equal(_maple_values(path).omega.values, _maple_values(MAPLE).omega.values)
    filled = tmp_path / "filled.csv"
    lines = MAPLE.read_text().splitlines()
    filled.write_text("\n".join([lines[0] + ",", *(line + ",7" for line in lines[1:])]) + "\n")
    with pytest.raises(InputError, match=r"column 12 has values \(line 2, \.\.\.\) but no name in the header"):
        ingest(filled, BALLS, MAPLE_BATS)


def test_a_directory_is_named_as_such(tmp_path):
    with pytest.raises(InputError) as err:
        ingest(tmp_path, BALLS, MAPLE_BATS)
    assert f"{tmp_path}: is a directory, not a CSV file" in err.value.problems
