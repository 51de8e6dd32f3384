"""Measured datasets: every bad input is named (file, row, column, problem), all at once."""

from __future__ import annotations

import copy
import csv
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr
import yaml

from ballbat import ingest
from ballbat.config_checks import validate_config
from ballbat.fitting import FitStatus
from ballbat.kinematics import ImpactFlag
from ballbat.pipeline.config import ConfigError
from ballbat.pipeline.ncio import check_metadata
from ballbat.properties import InputError, load_balls, load_bats
from ballbat.stages import fit_ex, normalize, reconstruct
from ballbat.stages import ingest as ingest_stage
from ballbat.units import DEGREE, MPH, RPM
from workflow_helpers import ROOT

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


NORM = normalize.NormalizeSettings(v_ref_mph=77.0)
REC = reconstruct.ReconstructSettings()
FIT = fit_ex.FitExSettings(mu_k_example=0.5, systematic=True, check_physical=True)


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
    # and the fit refuses the e_x it gives (tests/test_plausibility.py)
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


@pytest.fixture(scope="module")
def schema_and_base():
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    return schema, base


def test_config_measured_dataset(schema_and_base):
    schema, base = schema_and_base
    cfg = copy.deepcopy(base)
    cfg["datasets"].update(yaml.safe_load((ROOT / "config" / "examples" / "maple.yaml").read_text())["datasets"])
    validate_config(cfg, schema)
    assert cfg["datasets"]["maple"]["bats"] == "config/examples/maple_bats.csv"
    # the synthetic dataset still gets its defaults
    assert cfg["datasets"]["synthetic"]["synthetic"]["noise"]["omega_rpm"] == 75.0


@pytest.mark.parametrize(
    ("dataset", "message"),
    [
        ({"impacts": "x.csv", "synthetic": {"impacts": {}, "e_x": {}, "e_y": {}}}, "give exactly one of synthetic"),
        ({"bats": "b.csv"}, "matches none of the allowed forms"),
        ({"impacts": "x.csv", "format": "csv"}, "datasets.m.format: unknown key"),
        ({"impacts": ""}, "datasets.m.impacts"),
    ],
)
def test_config_bad_dataset_forms(schema_and_base, dataset, message):
    schema, base = schema_and_base
    cfg = copy.deepcopy(base)
    cfg["datasets"]["m"] = dataset
    with pytest.raises(ConfigError, match=r"datasets\.m"):
        validate_config(cfg, schema)
    try:
        validate_config(cfg, schema)
    except ConfigError as exc:
        assert message in str(exc)


def test_ingest_job_imports_no_fitting_or_plotting():
    from ballbat.pipeline.codedeps import module_names

    mods = module_names(str(ROOT / "workflow" / "scripts" / "ingest.py"))
    assert "ballbat.fitting" not in mods
    code = "import sys\n" + "".join(f"import {m}\n" for m in mods)
    code += "print(sorted(m for m in ('lmfit', 'matplotlib') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
