"""Tables I-II (ballbat.properties): bat and ball tables in the paper's convention or a lab's, their checks,
the recoil factors, the properties' stated uncertainties (issue 35).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from helpers import HICKORY_HEAD
from helpers import write_table as _write

from ballbat import batlab
from ballbat.properties import (
    InputError,
    ball_variants,
    bat_record,
    bat_variants,
    load_balls,
    load_bats,
    recoil_factors,
    recoil_normal,
    recoil_tangential,
)
from ballbat.stages import fit_ex, ingest, normalize, reconstruct
from ballbat.units import INCH, OUNCE, OZ_IN2


def test_tables_load_in_si(balls, bats):
    # Table I: baseball 5.04 oz, 1.42 in; Table II: wood bat 29.41 oz, I0 2370 oz-in^2.
    assert balls["baseball"].m == pytest.approx(5.04 * OUNCE, rel=1e-12)
    assert balls["softball"].r == pytest.approx(1.90 * INCH, rel=1e-12)
    assert bats["wood"].I0 == pytest.approx(2370 * OZ_IN2, rel=1e-12)
    assert bats["metal_smooth"].Iz == pytest.approx(18.3 * OZ_IN2, rel=1e-12)
    assert set(bats) == {"wood", "metal_rough", "metal_smooth", "softball_composite"}


def test_recoil_factors_by_hand(balls, bats):
    # Eq. ry and Eq. rx evaluated by hand in paper units (ratios are unit-free).
    m, M, I0, Iz, b, R = 5.04, 29.41, 2370.0, 9.1, 6.8, 1.16
    ry = m * (1 / M + b**2 / I0)
    rx = m * 0.4 / 1.4 * (1 / M + b**2 / I0 + R**2 / Iz)
    got_rx, got_ry = recoil_factors(balls["baseball"], bats["wood"])
    assert got_ry == pytest.approx(ry, rel=1e-12)
    assert got_rx == pytest.approx(rx, rel=1e-12)
    assert recoil_normal(1.0, np.inf, np.inf, 0.0) == 0.0  # a massive bat does not recoil
    assert recoil_tangential(1.0, np.inf, np.inf, np.inf, 0.0, 1.0) == 0.0


def test_bad_table_lists_every_problem(tmp_path):
    p = tmp_path / "bats.csv"
    p.write_text("bat,name,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in,colour\nx,,-1,abc,9,6,1.1,red\nx,,30,2000,,6,1.1,blue\n")
    with pytest.raises(InputError) as exc:
        load_bats(p)
    msg = str(exc.value)
    assert f"{p}: unknown column(s) colour" in msg
    assert f"{p}: row 2, column M_oz: -1 must be positive" in msg
    assert f"{p}: row 2, column I0_oz_in2: 'abc' is not a number" in msg
    assert f"{p}: row 3, column Iz_oz_in2: empty" in msg
    assert f"{p}: row 3, column bat: 'x' duplicates row 2" in msg


def test_missing_columns_and_file(tmp_path):
    p = tmp_path / "balls.csv"
    p.write_text("ball,m_oz\nbaseball,5\n")
    with pytest.raises(InputError, match=r"missing column\(s\) r_in"):
        load_balls(p)
    with pytest.raises(InputError, match="file not found"):
        load_balls(tmp_path / "nope.csv")


ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "config" / "examples"
#: The truth make_hickory.py draws the impacts with.
E_X_TRUE = 0.455
PAPER_HEADER = "bat,name,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in\n"
LAB_HEADER = (
    "bat,name,convention,length_in,weight_oz,balance_in,pivot_in,moi_oz_in2,impact_from_tip_in,diameter_in,Iz_oz_in2\n"
)


def _problems(tmp_path: Path, text: str) -> str:
    path = tmp_path / "bats.csv"
    path.write_text(text)
    with pytest.raises(InputError) as exc:
        load_bats(path)
    return str(exc.value)


def test_lab_row_converted_by_the_parallel_axis_theorem(tmp_path):
    bat = load_bats(EXAMPLES / "hickory_bats.csv")["hickory"]
    # I0 = I_p - M d^2 = 11200 - 32 (23 - 6)^2 = 1952 oz in^2; b = 34 - 6 - 23 = 5 in; R = 2.6 / 2
    assert bat.I0 / OZ_IN2 == pytest.approx(1952.0, rel=1e-12)
    assert bat.b / INCH == pytest.approx(5.0, rel=1e-12)
    assert bat.R / INCH == pytest.approx(1.3, rel=1e-12)
    assert bat.convention == "lab" and json.loads(bat.given)["moi_oz_in2"] == "11200"


def test_hickory_in_the_paper_columns_is_refused_naming_the_lab_convention(tmp_path):
    msg = _problems(tmp_path, PAPER_HEADER + "hickory,hickory,32,11200,11.0,6,1.3\n")
    assert "row 2, column I0_oz_in2" in msg and "radius of gyration" in msg
    assert "6-in pivot" in msg and "lab convention" in msg and "convention = lab" in msg


def test_grams_as_ounces_and_b_outside_any_bat(tmp_path):
    msg = _problems(tmp_path, PAPER_HEADER + "w,w,907,2370,9.1,60,1.16\n")
    assert "row 2, column M_oz: 907 oz" in msg and "grams typed as ounces? (907 g = 32.0 oz)" in msg
    assert "row 2, column b_in: 60 in is outside any bat's barrel" in msg and "from the knob or the tip" in msg


@pytest.mark.parametrize(
    ("row", "where", "hint"),
    [
        ("h,h,lab,86.4,32,23,6,11200,6,2.6,11", "column length_in", "centimetres typed as inches"),
        ("h,h,lab,34,32,11,6,11200,6,2.6,11", "column balance_in", "measured from the barrel tip?"),
        ("h,h,lab,34,32,23,6,11200,28,2.6,11", "column impact_from_tip_in", "measured from the knob?"),
        ("h,h,lab,34,32,23,6,1952,6,2.6,11", "column moi_oz_in2", "about the centre of mass given as about the pivot"),
        ("h,h,lab,34,32,23,6,11200,6,1.3,11", "column diameter_in", "the radius given as the diameter"),
        ("h,h,lab,34,32,23,6,17000,6,2.6,11", "column moi_oz_in2", "an MOI about the knob end"),
        ("h,h,lab,34,32,23,6,9700,6,2.6,11", "column moi_oz_in2", "given as about the pivot"),
        ("h,h,lab,34,32,23,6,11200,6,2.6,110", "column Iz_oz_in2", "radius of gyration about the long axis"),
    ],
)
def test_lab_rows_checked_with_the_likely_mistake(tmp_path, row, where, hint):
    msg = _problems(tmp_path, LAB_HEADER + row + "\n")
    assert f"row 2, {where}" in msg and hint in msg


def test_centre_of_percussion_checked_when_given(tmp_path):
    cop = batlab.centre_of_percussion(
        {"weight_oz": 32.0, "balance_in": 23.0, "pivot_in": 6.0, "moi_oz_in2": 11200.0}
    )  # 6 + 11200 / (32 * 17) = 26.59 in
    assert cop == pytest.approx(6 + 11200 / (32 * 17), rel=1e-12)
    path = tmp_path / "bats.csv"
    path.write_text(LAB_HEADER.rstrip("\n") + ",cop_in\n" + "h,h,lab,34,32,23,6,11200,6,2.6,11,26.6\n")
    assert "h" in load_bats(path)
    msg = _problems(tmp_path, LAB_HEADER.rstrip("\n") + ",cop_in\n" + "h,h,lab,34,32,23,6,11200,6,2.6,11,24.0\n")
    assert "column cop_in" in msg and "26.59" in msg


@pytest.mark.parametrize(
    ("header", "words"),
    [
        ("bat,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in,balance_in", "balance_in belong to the lab"),
        ("bat,convention,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in", "belong to the paper"),
        ("bat,length_in,weight_oz,balance_in,pivot_in,moi_oz_in2,impact_from_tip_in,diameter_in,Iz_oz_in2", "state it"),
        ("bat,mass,inertia", "fit neither convention"),
        (LAB_HEADER.strip().replace(",impact_from_tip_in", ""), "impact_from_tip_in or impact_from_knob_in"),
    ],
)
def test_tables_fitting_neither_convention_or_mixing_them_name_the_columns(tmp_path, header, words):
    n = header.count(",") + 1
    value = {"bat": "x", "convention": "lab"}
    cells = [value.get(c, "1") for c in header.split(",")]
    assert len(cells) == n
    msg = _problems(tmp_path, header + "\n" + ",".join(cells) + "\n")
    assert words in msg


def test_hickory_in_the_lab_convention_gives_e_x_within_one_standard_error(config):
    balls = load_balls(ROOT / "config" / "balls.csv")
    bats = load_bats(EXAMPLES / "hickory_bats.csv")
    ds = ingest.run(
        ingest.IngestSettings(calibration={}),
        EXAMPLES / "hickory_impacts.csv",
        ROOT / "config" / "balls.csv",
        EXAMPLES / "hickory_bats.csv",
    )
    rec = reconstruct.run(
        reconstruct.ReconstructSettings(),
        normalize.run(normalize.NormalizeSettings.from_config(config), ds),
        balls,
        bats,
    )
    fit = fit_ex.run(fit_ex.FitExSettings.from_config(config), rec)
    got = fit.sel(ball="baseball", bat="hickory")
    assert abs(float(got.e_x) - E_X_TRUE) < float(got.e_x_err)
    # every product records the table as given and the values used
    record = json.loads(fit.attrs["bat_properties"])["hickory"]
    assert record["convention"] == "lab" and record["as_given"]["balance_in"] == "23.0"
    assert record["used"]["I0_oz_in2"] == pytest.approx(1952.0) and record["used"]["b_in"] == pytest.approx(5.0)
    assert isinstance(fit, xr.Dataset)


EX = ROOT / "config" / "examples"
BALLS = ROOT / "config" / "balls.csv"
MAPLE_HEAD = "bat,name,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in"
MAPLE_ROW = "maple,maple,{M},{I0},9.6,6.5,1.24"
HICKORY_ROW = "hickory,hickory,lab,34,{w},{bp},6,{moi},6,2.6,11.0"


# ---------------------------------------------------------------------------------------
# reading: both conventions, the checks


def test_paper_table_with_err_columns(tmp_path):
    path = _write(
        tmp_path / "b.csv", MAPLE_HEAD + ",M_oz_err,I0_oz_in2_err", MAPLE_ROW.format(M=31.0, I0=2480) + ",0.3,25"
    )
    bat = load_bats(path)["maple"]
    assert json.loads(bat.err) == {"M_oz": 0.3, "I0_oz_in2": 25.0}
    got = {col: (value, sigma, plus, minus) for col, value, sigma, plus, minus in bat_variants(bat)}
    value, sigma, plus, minus = got["M_oz"]
    assert (value, sigma) == (31.0, 0.3)
    assert plus.M / bat.M == pytest.approx(31.3 / 31.0, rel=1e-12)
    assert minus.M / bat.M == pytest.approx(30.7 / 31.0, rel=1e-12)
    assert plus.I0 == bat.I0 and plus.b == bat.b  # one property moves, nothing else
    # the products record the uncertainties with the table as given and the values used
    assert json.loads(bat_record({"maple": bat}))["maple"]["uncertainty"] == {"I0_oz_in2": 25.0, "M_oz": 0.3}
    assert "uncertainty" not in json.loads(bat_record(load_bats(EX / "maple_bats.csv")))["maple"]


def test_lab_table_with_err_columns_converted_again(tmp_path):
    """A lab value's +-1 sigma goes through the conversion again: the balance point moves I0 and b together."""
    row = HICKORY_ROW.format(w=32, bp=23.0, moi=11200) + ",0.1,0.1,112"
    path = _write(tmp_path / "h.csv", HICKORY_HEAD + ",weight_oz_err,balance_in_err,moi_oz_in2_err", row)
    bat = load_bats(path)["hickory"]
    got = {col: (plus, minus) for col, _, _, plus, minus in bat_variants(bat)}
    assert set(got) == {"weight_oz", "balance_in", "moi_oz_in2"}
    for col, delta in (("balance_in", 0.1), ("weight_oz", 0.1), ("moi_oz_in2", 112.0)):
        for moved, side in zip(got[col], (1, -1), strict=True):
            lab = {"length_in": 34, "weight_oz": 32, "balance_in": 23.0, "pivot_in": 6, "moi_oz_in2": 11200}
            lab |= {"impact_from_tip_in": 6, "diameter_in": 2.6, "Iz_oz_in2": 11.0}
            lab[col] += side * delta
            expect = batlab.paper_row(lab)  # the conversion of docs/model.md, by hand at the moved value
            assert moved.I0 == pytest.approx(expect["I0_oz_in2"] * OZ_IN2, rel=1e-12)
            assert moved.b == pytest.approx(expect["b_in"] * INCH, rel=1e-12)
            assert moved.M == pytest.approx(expect["M_oz"] * OUNCE, rel=1e-12)
    # the balance point moves the impact point from the centre of mass by -sigma exactly (b = x_impact - x_cm)
    plus, _ = got["balance_in"]
    assert (plus.b - bat.b) / 0.0254 == pytest.approx(-0.1, abs=1e-12)


@pytest.mark.parametrize(
    ("head", "row", "column", "words"),
    [
        (MAPLE_HEAD + ",M_oz_err", MAPLE_ROW.format(M=31.0, I0=2480) + ",-0.3", "M_oz_err", "negative"),
        (MAPLE_HEAD + ",b_in_err", MAPLE_ROW.format(M=31.0, I0=2480) + ",4", "b_in_err", "a percentage?"),
        (
            HICKORY_HEAD + ",moi_oz_in2_err",
            HICKORY_ROW.format(w=32, bp=23.0, moi=11200) + ",9000",
            "moi_oz_in2_err",
            "more than 50%",
        ),
    ],
)
def test_bad_err_refused_naming_file_row_column(tmp_path, head, row, column, words):
    path = _write(tmp_path / "bad.csv", head, row)
    with pytest.raises(InputError) as exc:
        load_bats(path)
    assert f"{path}: row 2, column {column}" in str(exc.value) and words in str(exc.value)


def test_err_of_a_column_the_table_has_not_is_unknown(tmp_path):
    row = HICKORY_ROW.format(w=32, bp=23.0, moi=11200) + ",0.01"
    path = _write(tmp_path / "h.csv", HICKORY_HEAD + ",period_s_err", row)
    with pytest.raises(InputError, match=r"unknown column.*period_s_err"):
        load_bats(path)


def test_ball_table_err_and_bad_err(tmp_path):
    text = BALLS.read_text().splitlines()
    good = tmp_path / "balls.csv"
    good.write_text("\n".join([text[0] + ",m_oz_err", *(t + ",0.02" for t in text[1:])]) + "\n")
    ball = load_balls(good)["baseball"]
    (col, value, sigma, plus, minus), *_ = ball_variants(ball)
    assert (col, value, sigma) == ("m_oz", 5.04, 0.02)
    assert (plus.m - minus.m) / ball.m == pytest.approx(0.04 / 5.04, rel=1e-12)
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join([text[0] + ",r_in_err", text[1] + ",-0.01", text[2] + ",0.01"]) + "\n")
    with pytest.raises(InputError, match=r"bad.csv: row 2, column r_in_err: -0.01 is negative"):
        load_balls(bad)


def test_shipped_tables_state_no_uncertainty():
    """Table II gives none, so the shipped tables invent none: no property source in the default run."""
    assert all(not b.err for b in load_bats(ROOT / "config" / "bats.csv").values())
    assert all(not b.err for b in load_balls(BALLS).values())


def test_drawn_properties_scatter_by_the_stated_sigma():
    """The truth a replicate is drawn with differs from the sheet by N(0, sigma) in each measured value."""
    from ballbat.properties import drawn_properties

    bats = load_bats(EX / "property_study_bats.csv")
    balls = load_balls(BALLS)
    rng = np.random.default_rng(1)
    n = 2000
    draws = [drawn_properties(bats, balls, rng) for _ in range(n)]
    z = np.array([[d[2][k] for k in sorted(d[2])] for d in draws])
    assert sorted(draws[0][2]) == [
        f"bat:hickory:{c}" for c in ("balance_in", "impact_from_tip_in", "moi_oz_in2", "weight_oz")
    ]
    # z is standard normal: mean 0 and sd 1 within 4 standard errors of n draws
    assert np.all(np.abs(z.mean(axis=0)) < 4 / np.sqrt(n))
    assert np.all(np.abs(z.std(axis=0, ddof=1) - 1) < 4 / np.sqrt(2 * n))
    # the bat's mass is the drawn weight: (M - M_sheet) / sigma is that z exactly
    mass = np.array([d[0]["hickory"].M for d in draws]) / OUNCE
    assert np.allclose((mass - 32.0) / 0.1, z[:, 3], atol=1e-9)
    # the MOI's 3 % moves I0 by 336 oz in^2 per z (I0 = I_p - M d^2), with the others' draws on top
    i0 = np.array([d[0]["hickory"].I0 for d in draws]) / OZ_IN2
    lab = {"length_in": 34, "weight_oz": 32, "balance_in": 23.0, "pivot_in": 6, "moi_oz_in2": 11200}
    lab |= {"impact_from_tip_in": 6, "diameter_in": 2.6, "Iz_oz_in2": 11.0}
    order = ("balance_in", "impact_from_tip_in", "moi_oz_in2", "weight_oz")
    sig = {"balance_in": 0.1, "impact_from_tip_in": 0.25, "moi_oz_in2": 336.0, "weight_oz": 0.1}
    expect = [batlab.moved_row(lab, {c: zz * sig[c] for c, zz in zip(order, row, strict=True)}, "lab") for row in z[:5]]
    assert np.allclose(i0[:5], [e["I0_oz_in2"] for e in expect], rtol=1e-12)
    assert np.std(i0, ddof=1) == pytest.approx(
        np.sqrt(336.0**2 + (2 * 32 * 17 * 0.1) ** 2 + (17**2 * 0.1) ** 2), rel=0.08
    )
    # no stated uncertainty: nothing drawn, the tables as they are
    plain = load_bats(ROOT / "config" / "bats.csv")
    assert drawn_properties(plain, balls, rng)[2] == {}
