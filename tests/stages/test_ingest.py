"""The ingest stage (ballbat.stages.ingest): a measured impacts file, every bad input named (file, row, column,
problem) all at once; per-row plausibility, unit mistakes named as such (issue 10, item 1; issue 35, item 5).
"""

from __future__ import annotations

import copy
import csv
import math
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr
from conftest import ROOT
from helpers import FIT, NORM, REC

from ballbat import ingest
from ballbat.fitting import FitStatus, ImplausibleFit
from ballbat.kinematics import ImpactFlag
from ballbat.pipeline.ncio import check_metadata
from ballbat.properties import InputError, load_balls, load_bats
from ballbat.stages import fit_ex, normalize, reconstruct, simulate
from ballbat.stages import ingest as ingest_stage
from ballbat.stages import ingest as ingest_stages
from ballbat.synthetic import SyntheticSettings
from ballbat.units import DEGREE, MPH, RPM

EXAMPLE = ROOT / "config" / "examples" / "maple_impacts.csv"
MAPLE_BATS = ROOT / "config" / "examples" / "maple_bats.csv"
BALLS = ROOT / "config" / "balls.csv"
BATS = ROOT / "config" / "bats.csv"

HEADER = ["impact_id", "bat", "ball", "v_bat_mph", "v_ball_mph", "theta_deg", "omega_rpm"]
GOOD = [  # wood bat, baseball: plausible impacts (Sec. III forward model, e_x ~ 0.46)
    ["A1", "wood", "baseball", "75.0", "84.0", "10.0", "1900"],
    ["A2", "wood", "baseball", "80.0", "88.5", "14.0", "2700"],
    ["A3", "wood", "baseball", "70.0", "80.0", "5.0", "900"],
    ["A4", "wood", "baseball", "85.0", "92.0", "16.0", "3200"],
]


def ingested(path, balls=BALLS, bats=BATS):
    """The ingest stage's file of ``path`` and its warnings."""
    ds = ingest_stage.run(ingest_stage.IngestSettings(calibration={}), path, balls, bats)
    return ds, ingest_stage.warnings(ds)


def write_csv(path, rows, header=HEADER):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(header)
        w.writerows(rows)
    return path


def example_rows() -> list[dict]:
    with open(EXAMPLE, newline="") as fh:
        return list(csv.DictReader(fh))


def problems_of(path, balls=BALLS, bats=BATS) -> list[str]:
    with pytest.raises(InputError) as exc:
        ingested(path, balls, bats)
    return exc.value.problems


def one(problems, *parts):
    """The one problem that contains every part."""
    hits = [p for p in problems if all(s in p for s in parts)]
    assert len(hits) == 1, (parts, problems)
    return hits[0]


# ---------------------------------------------------------------------------------------
# The example dataset


def test_example_reads_clean():
    ds, warnings = ingested(EXAMPLE, BALLS, MAPLE_BATS)
    check_metadata(ds, "ingest")
    assert warnings == []
    assert ds.sizes["impact"] == 31 and set(ds["bat"].values) == {"maple"}
    assert ds["v_bat"].values[0] == pytest.approx(68.7 * MPH)
    assert ds["omega"].values[0] == pytest.approx(947 * RPM)
    assert ds["theta_err"].values[0] == pytest.approx(0.5 * DEGREE)
    assert ds.attrs["n_excluded"] == 1 and ds.attrs["ingest_warnings"] == ""
    i = int(np.flatnonzero(ds["ingest_flag"].values)[0])
    assert ds["impact_id"].values[i] == "MP31" and ds["source_row"].values[i] == "row 32"
    assert "psi cannot be reconstructed" in ds["ingest_flag_reason"].values[i]
    assert ingest_stage.excluded_listing(ds) == [
        "impact MP31 (row 32): alpha r omega / v_ball = 1.04: psi cannot be reconstructed (Eq. angmom)"
    ]


def test_exclusion_reaches_reconstruct_and_is_kept_out_of_fits():
    ds, _ = ingested(EXAMPLE, BALLS, MAPLE_BATS)
    rec = reconstruct.run(REC, normalize.run(NORM, ds), load_balls(BALLS), load_bats(MAPLE_BATS))
    check_metadata(rec, "reconstruct")
    excluded = rec["flag"].values == ImpactFlag.EXCLUDED_AT_INGEST
    assert excluded.sum() == 1 and (rec["flag"].values[~excluded] == 0).all()
    assert rec["flag_reason"].values[excluded][0].startswith("excluded at ingest: alpha r omega / v_ball")
    meanings = rec["flag"].attrs["flag_meanings"].split()
    assert meanings[list(rec["flag"].attrs["flag_values"]).index(4)] == "excluded_at_ingest"
    fit = fit_ex.run(FIT, rec)
    assert int(fit["e_x_n"].sel(ball="baseball", bat="maple")) == 30
    assert int(fit["e_x_status"].sel(ball="baseball", bat="maple")) == FitStatus.OK
    assert fit.attrs["n_excluded"] == 1
    # the example's truth: e_x = 0.42 (config/examples/make_maple.py)
    e_x, err = (float(fit[v].sel(ball="baseball", bat="maple")) for v in ("e_x", "e_x_err"))
    assert abs(e_x - 0.42) < 3 * err


def test_netcdf_same_content(tmp_path):
    rows = example_rows()
    cols = {k: [r[k] for r in rows] for k in rows[0]}
    data = {
        k: ("impact", np.array(v, dtype=float if k not in ("impact_id", "bat", "ball") else str))
        for k, v in cols.items()
    }
    xr.Dataset(data).to_netcdf(tmp_path / "maple.nc")
    a, _ = ingested(EXAMPLE, BALLS, MAPLE_BATS)
    b, _ = ingested(tmp_path / "maple.nc", BALLS, MAPLE_BATS)
    for v in ("v_bat", "v_ball", "theta", "omega", "omega_err", "ingest_flag"):
        np.testing.assert_allclose(a[v].values, b[v].values)
    assert b["source_row"].values[3] == "entry 4"
    # a variable whose units contradict its name
    ds = xr.Dataset(data)
    ds["v_bat_mph"].attrs["units"] = "m s-1"
    ds.to_netcdf(tmp_path / "bad.nc")
    one(problems_of(tmp_path / "bad.nc", bats=MAPLE_BATS), "bad.nc", "variable v_bat_mph", "units 'm s-1'")


# ---------------------------------------------------------------------------------------
# Problems that stop the dataset: file, row (CSV line), column, what is wrong


def test_missing_file(tmp_path):
    one(problems_of(tmp_path / "nope.csv"), "nope.csv", "file not found")


def test_missing_columns(tmp_path):
    path = write_csv(tmp_path / "m.csv", [r[:6] for r in GOOD], HEADER[:6])
    one(problems_of(path), "m.csv", "missing column(s) omega_rpm", "required:")


def test_unknown_and_repeated_columns(tmp_path):
    path = write_csv(tmp_path / "u.csv", [[*r, "0.5", "1"] for r in GOOD], [*HEADER, "theta_deg_error", "impact_id"])
    probs = problems_of(path)
    one(probs, "u.csv", "unknown column(s) 'theta_deg_error'", "allowed:")
    one(probs, "u.csv", "column(s) impact_id appear more than once")


def test_non_numeric_empty_and_non_finite(tmp_path):
    rows = copy.deepcopy(GOOD)
    rows[1][4] = "fast"  # line 3
    rows[2][5] = ""  # line 4
    rows[3][6] = "inf"  # line 5
    probs = problems_of(write_csv(tmp_path / "n.csv", rows))
    one(probs, "n.csv: row 3, column v_ball_mph", "'fast' is not a number")
    one(probs, "n.csv: row 4, column theta_deg", "empty")
    one(probs, "n.csv: row 5, column omega_rpm", "'inf' is not finite")
    assert len(probs) == 3  # all at once, nothing else


BAD_CELLS = {  # (row of GOOD, column) -> the value a lab typed: each must be named with its row and column
    "speeds": {
        (0, 3): ("-75", "s.csv: row 2, column v_bat_mph", "-75 mph; a speed must be positive"),
        (2, 4): ("0", "s.csv: row 4, column v_ball_mph", "0 mph; a speed must be positive"),
    },
    "angles": {
        (1, 5): ("95", "s.csv: row 3, column theta_deg", "95 deg is outside the physical range (-90, 90)"),
        (2, 5): ("-90", "s.csv: row 4, column theta_deg", "-90 deg is outside"),
    },
    "names": {
        (0, 1): ("ash", "s.csv: row 2, column bat", "bat 'ash' is not in the bat table", "known: metal_rough"),
        (3, 2): (
            "cricket",
            "s.csv: row 5, column ball",
            "ball 'cricket' is not in the ball table",
            "known: baseball, softball",
        ),
    },
}


@pytest.mark.parametrize("kind", sorted(BAD_CELLS))
def test_a_bad_cell_is_named_by_row_and_column(tmp_path, kind):
    """Non-positive speeds, angles outside (-90, 90) deg, bats and balls not in the tables."""
    rows = copy.deepcopy(GOOD)
    for (row, col), (value, *_) in BAD_CELLS[kind].items():
        rows[row][col] = value
    probs = problems_of(write_csv(tmp_path / "s.csv", rows))
    for _, *parts in BAD_CELLS[kind].values():
        one(probs, *parts)
    assert len(probs) == len(BAD_CELLS[kind]), probs


def test_duplicate_impact_ids(tmp_path):
    rows = copy.deepcopy(GOOD)
    rows[3][0] = "A1"
    probs = problems_of(write_csv(tmp_path / "d.csv", rows))
    one(probs, "d.csv: row 5, column impact_id", "'A1' duplicates row 2")


def test_bad_uncertainties_and_extra_cells(tmp_path):
    rows = [[*r, "0.5"] for r in copy.deepcopy(GOOD)]
    rows[1][-1] = "-0.5"
    rows[2].append("7")
    probs = problems_of(write_csv(tmp_path / "e.csv", rows, [*HEADER, "v_bat_mph_err"]))
    one(probs, "e.csv: row 3, column v_bat_mph_err", "-0.5 is negative")
    one(probs, "e.csv: row 4", "1 more cell(s) than the header has columns")


def test_header_only_and_empty_file(tmp_path):
    one(problems_of(write_csv(tmp_path / "h.csv", [])), "h.csv", "no impacts")
    (tmp_path / "z.csv").write_text("")
    one(problems_of(tmp_path / "z.csv"), "z.csv", "empty file")


def test_bad_property_table_reported_with_the_impacts(tmp_path):
    bats = tmp_path / "bats.csv"
    bats.write_text("bat,name,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in\nwood,wood,-29.4,2370,0,6.8,1.16\n")
    rows = copy.deepcopy(GOOD)
    rows[0][4] = "x"
    probs = problems_of(write_csv(tmp_path / "t.csv", rows), bats=bats)
    one(probs, "bats.csv: row 2, column M_oz", "must be positive")
    one(probs, "bats.csv: row 2, column Iz_oz_in2", "must be positive")
    one(probs, "t.csv: row 2, column v_ball_mph", "'x' is not a number")
    (tmp_path / "balls.csv").write_text("ball,m_oz\nbaseball,5.04\n")
    one(problems_of(write_csv(tmp_path / "t2.csv", GOOD), balls=tmp_path / "balls.csv"), "missing column(s) r_in")


def test_nothing_to_fit_stops(tmp_path):
    rows = copy.deepcopy(GOOD)[:2]
    one(problems_of(write_csv(tmp_path / "f.csv", rows)), "f.csv", "no ball x bat pair has 3 usable impacts", "nothing")


# ---------------------------------------------------------------------------------------
# Problems that exclude an impact, and warnings


def test_unreconstructable_psi_is_excluded_not_fatal(tmp_path):
    rows = copy.deepcopy(GOOD)
    rows.append(["A5", "wood", "baseball", "75.0", "40.0", "8.0", "30000"])  # line 6
    rows.append(["B1", "metal_rough", "baseball", "75.0", "84.0", "10.0", "1900"])
    ds, warnings = ingested(write_csv(tmp_path / "p.csv", rows), BALLS, BATS)
    assert ds["ingest_flag"].values.tolist() == [0, 0, 0, 0, 1, 0]
    assert ds["source_row"].values[4] == "row 6"
    assert "psi cannot be reconstructed" in ds["ingest_flag_reason"].values[4]
    one(warnings, "p.csv", "ball 'baseball' on bat 'metal_rough': 1 usable impact(s), fewer than 3", "not fitted")


def test_partial_uncertainties_warn(tmp_path):
    rows = [[*r, "0.5"] for r in GOOD]
    _, warnings = ingested(write_csv(tmp_path / "w.csv", rows, [*HEADER, "theta_deg_err"]), BALLS, BATS)
    one(warnings, "w.csv", "only theta_deg_err of the four uncertainty columns", "unweighted")


@pytest.mark.parametrize(
    ("column", "factor", "expected"),
    [
        ("omega_rpm", 1 / (60 / (2 * np.pi)), "column omega_rpm: most impacts are physically implausible"),
        ("v_bat_mph", MPH, "column v_bat_mph: most impacts are physically implausible"),
        ("v_ball_mph", MPH, "column v_ball_mph: most impacts are physically implausible"),
        ("omega_rpm", -1.0, "column omega_rpm: most impacts are physically implausible"),
        ("theta_deg", DEGREE, "column theta_deg: every |theta| is below 1.57 deg"),
    ],
)
def test_unit_mistakes_warn_naming_the_column(tmp_path, column, factor, expected):
    rows = example_rows()
    for r in rows:
        r[column] = f"{float(r[column]) * factor:.4g}"
    path = tmp_path / "units.csv"
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, list(rows[0]), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    hint = {
        ("omega_rpm", False): "spin in rad/s, not rpm",
        ("omega_rpm", True): "spin with the opposite sign",
        ("v_bat_mph", False): "bat speed in m/s, not mph",
        ("v_ball_mph", False): "exit speed in m/s, not mph",
        ("theta_deg", False): "radians, not degrees",
    }[(column, factor < 0)]
    try:
        ds, warnings = ingested(path, BALLS, MAPLE_BATS)
    except ingest.InputError as exc:  # most rows implausible: the dataset stops, the column named (issue 10)
        assert "more than half: the file's units are likely wrong" in exc.problems[0]
        one(exc.problems, "units.csv", expected, hint)
        return
    # a mistake most rows survive (the spin's sign, psi then negative but possible) is warned about,
    # and the fit refuses the e_x it gives (the plausibility tests below)
    one(warnings, "units.csv", expected, hint)
    assert hint in ds.attrs["ingest_warnings"] and ds.attrs["n_warnings"] == len(warnings)


# ---------------------------------------------------------------------------------------
# Fits of groups too small to fit, config forms, and the job's imports


def test_small_group_not_fitted(tmp_path):
    rows = [
        *copy.deepcopy(GOOD),
        ["B1", "metal_rough", "baseball", "75.0", "84.0", "10.0", "1900"],
        ["B2", "metal_rough", "baseball", "78.0", "86.0", "12.0", "2300"],
    ]
    ds, _ = ingested(write_csv(tmp_path / "g.csv", rows), BALLS, BATS)
    fit = fit_ex.run(FIT, reconstruct.run(REC, normalize.run(NORM, ds), load_balls(BALLS), load_bats(BATS)))
    small = fit.sel(ball="baseball", bat="metal_rough")
    assert np.isnan(float(small["e_x"])) and int(small["e_x_n"]) == 2
    assert int(small["e_x_status"]) == FitStatus.TOO_FEW_IMPACTS
    assert fit_ex.not_fitted(fit) == [
        "e_x (ball baseball, bat metal_rough): not fitted: too few impacts (2 usable impacts)"
    ]
    assert np.isfinite(float(fit["e_x"].sel(ball="baseball", bat="wood")))
    assert int(fit["e_x_pooled_n"].sel(ball="baseball")) == 6
    assert int(fit["e_x_status"].sel(ball="baseball", bat="wood")) == FitStatus.OK


def test_ingest_job_imports_no_fitting_or_plotting():
    from ballbat.pipeline.codedeps import module_names

    mods = module_names(str(ROOT / "workflow" / "scripts" / "ingest.py"))
    assert "ballbat.fitting" not in mods
    code = "import sys\n" + "".join(f"import {m}\n" for m in mods)
    code += "print(sorted(m for m in ('lmfit', 'matplotlib') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


MAPLE = ROOT / "config" / "examples" / "maple_impacts.csv"
RPM_PER_RAD_S = 2 * math.pi / 60


def ingest_plausibility(path, balls, bats):
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
    ds, _ = ingest_plausibility(path, BALLS, MAPLE_BATS)
    rec = reconstruct.run(
        reconstruct.ReconstructSettings(),
        normalize.run(normalize.NormalizeSettings(v_ref_mph=77.0), ds),
        load_balls(BALLS),
        load_bats(MAPLE_BATS),
    )
    return ds, fit_ex.run(
        fit_ex.FitExSettings(mu_k_example=0.5, systematic=True, check_physical=True, mu_k_bound=True), rec
    )


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
        ingest_plausibility(rewritten(tmp_path, columns, factor), BALLS, MAPLE_BATS)
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
    ds, _ = ingest_plausibility(path, BALLS, MAPLE_BATS)
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
        out, _ = ingest_plausibility(path, BALLS, ROOT / "config" / "bats.csv")
        flagged += int((out.ingest_flag.values == ImpactFlag.IMPLAUSIBLE).sum())
    assert flagged == 0


def test_rows_pasted_twice_are_an_error(tmp_path):
    """The same rows twice without impact_id (accepted before, shrinking the errors by sqrt 2)."""
    lines = [",".join(line.split(",")[1:]) for line in MAPLE.read_text().splitlines()]  # no impact_id
    path = tmp_path / "twice.csv"
    path.write_text("\n".join([*lines, *lines[1:4]]) + "\n")
    with pytest.raises(InputError) as err:
        ingest_plausibility(path, BALLS, MAPLE_BATS)
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
        ingest_plausibility(path, BALLS, MAPLE_BATS)
    assert err.value.problems == [f"{path}: variable omega_rpm_err: units 'rad s-1', expected 'rpm'"]


# ---------------------------------------------------------------------------------------
# CSV files as labs make them (issue 10, item 12)


def _maple_values(path):
    ds, _ = ingest_plausibility(path, BALLS, MAPLE_BATS)
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
        ingest_plausibility(path, BALLS, MAPLE_BATS)
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
        ingest_plausibility(filled, BALLS, MAPLE_BATS)


def test_a_directory_is_named_as_such(tmp_path):
    with pytest.raises(InputError) as err:
        ingest_plausibility(tmp_path, BALLS, MAPLE_BATS)
    assert f"{tmp_path}: is a directory, not a CSV file" in err.value.problems


def rewritten_unit_mistakes(tmp_path, column, factor, rows, keep_err=True):
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


def ingested_unit_mistakes(path):
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
    ds, _ = ingested_unit_mistakes(rewritten_unit_mistakes(tmp_path, column, factor, [row]))
    assert ds.ingest_flag.values[row] == ImpactFlag.IMPLAUSIBLE
    reason = str(ds.ingest_flag_reason.values[row])
    assert reason.startswith("implausible: ") and f"likely a unit mistake: column {column}" in reason
    assert f"the row fits {unit} far better" in reason
    assert (ds.ingest_flag.values != 0).sum() == 1  # no other row


def test_every_row_of_a_mixed_file_names_the_unit(tmp_path):
    """12 of 30 rows with spin in rad/s: each excluded row names rad/s."""
    ds, _ = ingested_unit_mistakes(rewritten_unit_mistakes(tmp_path, "omega_rpm", RPM_PER_RAD_S, range(12)))
    bad = ds.ingest_flag.values == ImpactFlag.IMPLAUSIBLE
    assert bad.sum() >= 10
    assert all("spin in rad/s, not rpm far better" in str(r) for r in ds.ingest_flag_reason.values[bad])


def test_a_kept_row_that_fits_another_unit_is_a_warning(tmp_path):
    """Without uncertainty columns, a rad/s row at small psi is not excluded (it is within the
    file's spread): it was fitted with 0 warnings; now it is named with its line and the unit.
    """
    ds, warnings = ingested_unit_mistakes(
        rewritten_unit_mistakes(tmp_path, "omega_rpm", RPM_PER_RAD_S, [3], keep_err=False)
    )
    assert ds.ingest_flag.values[3] == 0
    named = [w for w in warnings if ": row 5: column omega_rpm: the row fits spin in rad/s, not rpm far better" in w]
    assert len(named) == 1 and "a unit mistake in this row?" in named[0]


def test_clean_files_name_no_unit_mistake():
    for path, bats in ((MAPLE, MAPLE_BATS), (ROOT / "config" / "examples" / "hickory_impacts.csv", None)):
        bats = bats or ROOT / "config" / "examples" / "hickory_bats.csv"
        ds = ingest_stage.run(ingest_stage.IngestSettings(calibration={}), path, BALLS, bats)
        assert not any("unit mistake" in w for w in ingest_stage.warnings(ds))
        assert not any("unit mistake" in str(r) for r in ds.ingest_flag_reason.values)


def test_ingest_stage_keeps_warnings_and_exclusions():
    ds = ingest_stages.run(
        ingest_stages.IngestSettings(calibration={}), MAPLE, ROOT / "config" / "balls.csv", MAPLE_BATS
    )
    assert ds.attrs["n_warnings"] == len(ingest_stages.warnings(ds)) == 0
    assert ds.attrs["n_excluded"] == 1 and ds.sizes["impact"] == 31
    assert ingest_stages.excluded_listing(ds)[0].startswith("impact MP31 (row 32):")
    assert ds.attrs["source_file"] == str(MAPLE)


def test_a_ball_faster_than_any_collision_sends_it_is_named_even_where_psi_fails():
    """A bat at rest (a tip tracked on a still spot of the background: 4 mm/s, its swing plane garbage, so theta
    -97 deg) and a ball leaving at 34 m/s: psi cannot be reconstructed, and the reason is the exit speed, not a
    psi beyond 90 deg (before: "", left to the reconstruction's "the bat cannot reach the ball"). A plausible
    impact beside it gives no reason.
    """
    m = ingest.Measured(
        np.array([0.004, 30.0]),
        np.array([34.0, 35.0]),
        np.radians([-97.0, 20.0]),
        np.array([17.0, 170.0]),
        0.0366,
        0.4,
        1.2,
        0.02,
    )
    assert not ingest._collision_checks(m).ok[0]
    why = ingest.implausible_rows(m, np.array([0, 1]))
    assert "exceeds 2/(1 + r_y), the most any collision gives" in why[0], why
    assert why[1] == "", why
