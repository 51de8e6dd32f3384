"""Unit tests of the results workbooks (ballbat.workbook) on small in-memory results."""

from __future__ import annotations

import datetime as dt
import json
import re
import zipfile

import numpy as np
import openpyxl
import pytest
import xarray as xr
from helpers import WORKBOOK_PROVENANCE as PROVENANCE
from helpers import sheet_rows as rows
from helpers import workbook_impacts as impacts

from ballbat import workbook
from ballbat.fitting import FitStatus
from ballbat.pipeline.products import flag_attrs
from ballbat.pipeline.provenance import sha256_file
from ballbat.units import DEGREE, FOOT, INCH, MPH, RPM


def fit() -> xr.Dataset:
    """fit_ex.nc of two balls and two bats; softball x metal has no impacts (no row)."""
    dims = ("ball", "bat")
    per = {
        "e_x": [[0.4641, 0.3562], [0.2345, np.nan]],
        "e_x_err": [[0.0123, 0.0213], [0.0456, np.nan]],
        "e_x_err_scale": [[0.0050, 0.0040], [0.0010, np.nan]],
        "e_x_ci_low": [[0.44, 0.31], [0.14, np.nan]],
        "e_x_ci_high": [[0.49, 0.40], [0.33, np.nan]],
        "e_x_redchi": [[1.1, 0.9], [1.3, np.nan]],
    }
    data = {k: (dims, np.array(v)) for k, v in per.items()}
    data["e_x_n"] = (dims, np.array([[20, 19], [13, 0]]))
    data["e_x_status"] = (dims, np.array([[0, 0], [0, 3]]), flag_attrs(FitStatus))
    pooled = {"e_x_pooled": [0.41, 0.2345], "e_x_pooled_err": [0.011, 0.0456], "e_x_pooled_err_scale": [0.004, 0.001]}
    pooled |= {"e_x_pooled_ci_low": [0.39, 0.14], "e_x_pooled_ci_high": [0.43, 0.33], "e_x_pooled_redchi": [1.0, 1.3]}
    data |= {k: ("ball", np.array(v)) for k, v in pooled.items()}
    data["e_x_pooled_n"] = ("ball", np.array([39, 13]))
    data["e_x_pooled_status"] = ("ball", np.array([0, 0]), flag_attrs(FitStatus))
    sec4 = {
        "tan_ratio_slope": [0.51, 0.62],
        "tan_ratio_slope_err": [0.02, 0.03],
        "e_y_implied": [0.45, 0.32],
        "e_y_implied_err": [0.05, 0.06],
        "mu_k_lower_bound": [0.3, 0.4],
        "mu_k_lower_bound_err": [0.01, 0.02],
        "spin_theta_slope": [179.0 * RPM / DEGREE, 150.0 * RPM / DEGREE],
        "spin_theta_slope_err": [6.3 * RPM / DEGREE, 7.0 * RPM / DEGREE],
        "speed_theta_slope": [-0.25 * MPH / DEGREE, -0.3 * MPH / DEGREE],
        "speed_theta_slope_err": [0.012 * MPH / DEGREE, 0.02 * MPH / DEGREE],
        "spin_theta_slope_intercept": [2100.0 * RPM, 1900.0 * RPM],
        "speed_theta_slope_intercept": [95.0 * MPH, 85.0 * MPH],
        "gross_slip_psi": [np.radians(22.0), np.radians(30.0)],
        "gross_slip_theta": [np.radians(20.0), np.nan],
        "gross_slip_omega": [3000.0 * RPM, 2000.0 * RPM],
    }
    data |= {k: ("ball", np.array(v)) for k, v in sec4.items()}
    return xr.Dataset(
        data,
        coords={"ball": ["baseball", "softball"], "bat": ["wood", "metal"]},
        attrs={**PROVENANCE, "provenance_rule": "fit_ex", "title": "fit"},
    )


def stronge() -> xr.Dataset:
    return xr.Dataset(
        {
            "eta2": ("ball", np.array([4.9, 6.1])),
            "eta2_err": ("ball", np.array([0.23, 0.31])),
            "eta2_n": ("ball", np.array([58, 50])),
            "psi_stick_boundary": ("ball", np.radians([22.0, 25.5])),
        },
        coords={"ball": ["baseball", "softball"]},
        attrs={**PROVENANCE, "provenance_rule": "fit_stronge", "title": "stronge"},
    )


COMPARISON = [
    {"quantity": "e_x", "ball": "baseball", "bat": "wood", "paper": "0.464", "value": "0.4641", "unit": "1"},
    {"quantity": "e_x", "ball": "softball", "bat": "wood", "paper": "0.234", "value": "", "unit": "1"},
]


@pytest.fixture
def epoch(monkeypatch):
    """A fixed SOURCE_DATE_EPOCH (2020-01-02 03:04:05 UTC)."""
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1577934245")
    return dt.datetime(2020, 1, 2, 3, 4, 5)


@pytest.fixture
def book(tmp_path, epoch):
    path = tmp_path / "results.xlsx"
    workbook.dataset_workbook(path, impacts(), fit(), stronge(), COMPARISON, properties={"rule": "workbook"})
    return path


def test_the_league_entry_status_legend_is_fit_statuss():
    """The workbook states entry_status's codes (it does not import ballbat.fitting): they are FitStatus's."""
    assert workbook.LEGENDS["entry_status"] == {int(m): m.name.lower().replace("_", " ") for m in FitStatus}


def test_a_status_column_without_a_legend_is_refused(tmp_path):
    """A status column whose file states no meanings of its codes is not written unexplained."""
    ds = impacts()
    ds["flag"].attrs = {}
    with pytest.raises(ValueError, match="workbook sheet impacts: column flag has no legend of its codes"):
        workbook.dataset_workbook(tmp_path / "x.xlsx", ds, fit(), stronge(), COMPARISON)


def unit_of(words: str | None) -> str | None:
    """The unit a header in words states in its closing parentheses (None: no unit)."""
    m = re.search(r"\(([^()]+)\)$", words or "")
    return m.group(1) if m and m.group(1) in ("mph", "deg", "rpm", "in", "ft", "s", "mph/deg", "rpm/deg") else None


def formats(ws, row: int) -> list[str]:
    return [c.number_format for c in ws[row]]


def test_sheets_and_header_rows(book):
    wb = openpyxl.load_workbook(book)
    assert wb.sheetnames == [
        "impacts",
        "e_x",
        "sec4",
        "eta2",
        "systematics",
        "paper_comparison",
        "warnings",
        "legend",
        "provenance",
    ]
    ws = wb["impacts"]
    names = [
        "impact",
        "impact_id",
        "ball",
        "bat",
        "v_bat",
        "v_bat_err",
        "theta",
        "omega",
        "D",
        "r_x",
        "flag",
        "flag_reason",
    ]  # the columns of IMPACT_COLUMNS present in the file, in their order
    assert rows(ws)[0] == names
    assert [unit_of(w) for w in rows(ws)[1]] == [
        None,
        None,
        None,
        None,
        "mph",
        "mph",
        "deg",
        "rpm",
        "in",
        None,
        None,
        None,
    ]  # "1", text: none
    assert rows(ws)[1][2] == "ball type" and rows(ws)[1][4].startswith("v bat")  # words (no long_name here)
    assert ws.freeze_panes == "A3"
    assert ws.max_row == 2 + 3


def test_impacts_in_the_fields_units(book):
    ws = openpyxl.load_workbook(book)["impacts"]
    got = rows(ws)[2:]
    assert [r[:4] for r in got] == [
        [0, "A1", "baseball", "wood"],
        [1, "A2", "baseball", "wood"],
        [2, "A3", "softball", "metal"],
    ]
    np.testing.assert_allclose([r[4] for r in got], [70.0, 75.0, 80.0], rtol=1e-12)  # v_bat, mph
    np.testing.assert_allclose([r[6] for r in got], [10.0, -5.5, 20.25], rtol=1e-12)  # theta, deg
    assert got[0][7] == pytest.approx(1900.0, rel=1e-12) and got[1][7] is None  # NaN: an empty cell
    np.testing.assert_allclose([r[8] for r in got], [0.5, 1.25, -0.75], rtol=1e-12)  # D, in
    assert [r[10] for r in got] == [0, 0, 4] and all(type(r[10]) is int for r in got)  # counts stay integers
    assert [r[11] for r in got] == ["ok", "ok", "excluded at ingest"]
    # v_bat with its error: two significant digits of the error (0.50 mph, 0.25 mph: two decimals)
    assert formats(ws, 3)[4:6] == ["0.00", "0.00"]
    # without an error: the unit's decimals (deg 1, rpm 0, in 2, "1" 3); integers "0"; text untouched
    assert formats(ws, 3)[6:11] == ["0.0", "0", "0.00", "0.000", "0"]
    assert formats(ws, 3)[0] == "0" and formats(ws, 3)[1] == "General"


def test_e_x_sheet_rounds_to_the_finer_error(book):
    ws = openpyxl.load_workbook(book)["e_x"]
    table = rows(ws)
    assert table[0] == [
        "ball",
        "bat",
        "e_x",
        "e_x_err",
        "e_x_syst",  # the combined calibration systematic (here a file with the pixel scale's alone)
        "e_x_err_total",
        "e_x_ci_low",
        "e_x_ci_high",
        "e_x_n",
        "e_x_redchi",
        "e_x_status",
    ]
    assert [unit_of(w) for w in table[1]] == [None] * 11
    assert table[1][0] == "ball type" and table[1][5].startswith("total error of e_x")
    # per bat, then pooled; softball x metal (no impacts) has no row
    assert [r[:2] for r in table[2:]] == [
        ["baseball", "wood"],
        ["baseball", "metal"],
        ["baseball", "pooled"],
        ["softball", "wood"],
        ["softball", "pooled"],
    ]
    wood = table[2]
    assert wood[2:5] == pytest.approx([0.4641, 0.0123, 0.0050])
    assert wood[5] == pytest.approx(np.hypot(0.0123, 0.0050), rel=1e-12)  # statistical and systematic in quadrature
    assert wood[8:] == [20, 1.1, 0]  # impacts, reduced chi-square, status
    assert table[4][2:6] == pytest.approx([0.41, 0.011, 0.004, np.hypot(0.011, 0.004)])
    # the finer of the two errors sets the decimals: 0.0050 -> four; 0.0010 -> four; 0.0040 -> four
    assert formats(ws, 3)[2:8] == ["0.0000"] * 6
    assert formats(ws, 6)[2:8] == ["0.0000"] * 6
    assert formats(ws, 3)[8] == "0" and formats(ws, 3)[9] == "0.000"


def test_sec4_sheet_in_rpm_and_mph_per_degree(book):
    ws = openpyxl.load_workbook(book)["sec4"]
    table = rows(ws)
    head = dict(zip(table[0], map(unit_of, table[1]), strict=True))
    assert head["spin_theta_slope"] == "rpm/deg" and head["spin_theta_slope_err"] == "rpm/deg"
    assert head["speed_theta_slope"] == "mph/deg" and head["gross_slip_psi"] == "deg"
    assert head["gross_slip_omega"] == "rpm" and head["e_y_implied"] is None
    base = dict(zip(table[0], table[2], strict=True))
    assert base["ball"] == "baseball"
    assert base["spin_theta_slope"] == pytest.approx(179.0, rel=1e-12)
    assert base["spin_theta_slope_err"] == pytest.approx(6.3, rel=1e-12)
    assert base["speed_theta_slope"] == pytest.approx(-0.25, rel=1e-12)
    assert base["gross_slip_psi"] == pytest.approx(22.0, rel=1e-12)
    assert base["gross_slip_omega"] == pytest.approx(3000.0, rel=1e-12)
    assert dict(zip(table[0], table[3], strict=True))["gross_slip_theta"] is None  # NaN: empty
    fmt = dict(zip(table[0], formats(ws, 3), strict=True))
    assert fmt["spin_theta_slope"] == "0.0" and fmt["spin_theta_slope_err"] == "0.0"  # 6.3 rpm/deg
    assert fmt["speed_theta_slope"] == "0.000"  # 0.012 mph/deg: three decimals
    assert fmt["gross_slip_psi"] == "0.0" and fmt["gross_slip_omega"] == "0"


def test_eta2_comparison_and_warnings_sheets(book):
    wb = openpyxl.load_workbook(book)
    eta = rows(wb["eta2"])
    assert eta[0] == ["ball", "eta2", "eta2_err", "eta2_n", "psi_stick_boundary"]
    assert [unit_of(w) for w in eta[1]] == [None, None, None, None, "deg"]
    assert eta[2][:4] == ["baseball", 4.9, 0.23, 58] and eta[3][:4] == ["softball", 6.1, 0.31, 50]
    assert eta[3][4] == pytest.approx(25.5, rel=1e-12)
    assert formats(wb["eta2"], 3)[1:3] == ["0.00", "0.00"]  # 0.23: two decimals for eta2 and its error
    comp = rows(wb["paper_comparison"])
    assert comp[0] == ["quantity", "ball", "bat", "paper", "value", "unit"]
    assert comp[2] == ["e_x", "baseball", "wood", 0.464, 0.4641, 1.0]  # numbers as numbers
    assert comp[3][4] is None  # an empty value stays empty, not invented
    assert rows(wb["warnings"]) == [
        ["warning"],
        ["warning of the measured file"],
        ["first warning"],
        ["second warning"],
    ]


def test_provenance_sheet(book):
    table = rows(openpyxl.load_workbook(book)["provenance"])
    assert table[0] == ["file", "record", "key", "value"]
    records = {(r[0], r[1], r[2]): r[3] for r in table[2:]}
    assert records[("reconstruct.nc", "rule", None)] == "reconstruct"
    assert records[("fit_ex.nc", "rule", None)] == "fit_ex"
    assert records[("stronge.nc", "title", None)] == "stronge"
    assert records[("fit_ex.nc", "input", "results/t/normalize.nc")] == "ab12"
    assert records[("reconstruct.nc", "config", "v_ref_mph")] == "77.0"
    assert records[("stronge.nc", "software", "ballbat")] == '"9.9"'
    assert records[("fit_ex.nc", "git", "commit")] == '"unknown"'
    assert {r[0] for r in table[2:]} == {"reconstruct.nc", "fit_ex.nc", "stronge.nc"}


def test_document_time_and_custom_properties(book, epoch):
    wb = openpyxl.load_workbook(book)
    assert wb.properties.created == epoch and wb.properties.modified == epoch
    assert wb.properties.creator == "ballbat" and wb.properties.lastModifiedBy == "ballbat"
    assert {p.name: p.value for p in wb.custom_doc_props.props} == {"rule": "workbook"}
    with zipfile.ZipFile(book) as z:
        infos = z.infolist()
        assert [i.filename for i in infos] == sorted(i.filename for i in infos)
        assert {i.date_time for i in infos} == {(2020, 1, 2, 3, 4, 4)}  # zip keeps even seconds
        assert b"2020-01-02T03:04:05Z" in z.read("docProps/core.xml")


def test_rewrite_is_byte_identical(book, tmp_path):
    again = tmp_path / "again.xlsx"
    workbook.dataset_workbook(again, impacts(), fit(), stronge(), COMPARISON, properties={"rule": "workbook"})
    assert again.read_bytes() == book.read_bytes()
    assert not list(tmp_path.glob(".*.tmp"))  # written atomically: no temporary left


def test_document_time_sources(monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    assert workbook.document_time({"provenance_git": json.dumps({"commit": "unknown"})}) == workbook.FIXED_TIME
    assert workbook.document_time(None) == workbook.FIXED_TIME
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "0")
    assert workbook.document_time(None) == dt.datetime(1970, 1, 1)
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "not a number")
    assert workbook.document_time(None) == workbook.FIXED_TIME


def test_custom_properties_record_each_input(tmp_path):
    a = tmp_path / "fit_ex.nc"
    a.write_bytes(b"some bytes")
    deep = tmp_path.joinpath(*["d" * 100] * 3)  # a path longer than a property may be
    deep.mkdir(parents=True)
    b = deep / "stronge.nc"
    b.write_bytes(b"other bytes")
    props = workbook.custom_properties({"fit_ex.nc": a, "stronge.nc": b})
    assert props["input fit_ex.nc"] == f"{a} sha256:{sha256_file(a)}"
    long = props["input stronge.nc"]
    assert len(long) == 255 and long.endswith(f"stronge.nc sha256:{sha256_file(b)}")  # the hash is kept
    assert {"ballbat version", "ballbat source sha256", "workflow source sha256", "git commit", "git dirty"} <= set(
        props
    )
    assert all(isinstance(v, str) and len(v) <= 255 for v in props.values())


def test_implications_workbook(tmp_path, epoch):
    def scenario(carry_ft, title):
        n = len(carry_ft)
        return xr.Dataset(
            {
                "D": ("case", np.linspace(0.0, 1.0, n) * INCH),
                "exit_speed": ("case", np.full(n, 100.0) * MPH),
                "carry": ("case", np.array(carry_ft) * FOOT),
                "hang_time": ("case", np.full(n, 5.5)),
                "exceeds_mu": ("case", np.zeros(n, dtype=np.int8)),
            },
            coords={"case": np.arange(n)},
            attrs={**PROVENANCE, "provenance_rule": "implications", "title": title},
        )

    long_name = "a_scenario_with_a_very_long_name_indeed"
    path = tmp_path / "implications.xlsx"
    workbook.implications_workbook(path, {"paper": scenario([380.0, 400.5], "p"), long_name: scenario([350.25], "l")})
    wb = openpyxl.load_workbook(path)
    assert wb.sheetnames == [long_name[:31], "paper", "legend", "provenance"]  # sorted; Excel's 31-character limit
    paper = rows(wb["paper"])
    assert paper[0] == ["case", "D", "exit_speed", "carry", "hang_time", "exceeds_mu"]
    assert [unit_of(w) for w in paper[1]] == [None, "in", "mph", "ft", "s", None]
    assert [r[3] for r in paper[2:]] == pytest.approx([380.0, 400.5], rel=1e-12)
    assert paper[3][1] == pytest.approx(1.0, rel=1e-12) and paper[3][2] == pytest.approx(100.0, rel=1e-12)
    assert formats(wb["paper"], 3)[1:5] == ["0.00", "0.0", "0.0", "0.00"]  # in 2, mph 1, ft 1, s 2
    prov = {(r[0], r[1]) for r in rows(wb["provenance"])[2:]}
    assert ("paper.nc", "rule") in prov and (f"{long_name}.nc", "rule") in prov
    assert wb.properties.created == epoch
