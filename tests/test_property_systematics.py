"""Issue #35, item 4: bat and ball properties carry their uncertainties (``<column>_err``) to every result.

Each stated uncertainty is one systematic source (``bat:<bat>:<column>``, ``ball:<ball>:<column>``),
propagated as the tracks' calibrations are: the fits again with that one property at +1 and at -1
standard uncertainty for every impact of that bat (ball), half the difference. The hand computation
here writes the moved table itself and runs the chain on it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from ballbat import batlab, chain
from ballbat.properties import InputError, ball_variants, bat_record, bat_variants, load_balls, load_bats
from ballbat.units import INCH, OUNCE, OZ_IN2

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "config" / "examples"
BALLS = ROOT / "config" / "balls.csv"
MAPLE_HEAD = "bat,name,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in"
MAPLE_ROW = "maple,maple,{M},{I0},9.6,6.5,1.24"
HICKORY_HEAD = (
    "bat,name,convention,length_in,weight_oz,balance_in,pivot_in,moi_oz_in2,impact_from_tip_in,diameter_in,Iz_oz_in2"
)
HICKORY_ROW = "hickory,hickory,lab,34,{w},{bp},6,{moi},6,2.6,11.0"


def _write(path: Path, head: str, row: str) -> Path:
    path.write_text(f"{head}\n{row}\n")
    return path


def _chain(impacts: Path, bats: Path, balls: Path = BALLS):
    settings = chain.schema_settings({"impacts": str(impacts), "bats": str(bats)}, "lab")
    ds = chain.ingest(impacts, balls, bats)
    return chain.run(settings, ds, load_balls(balls), load_bats(bats))


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


# ---------------------------------------------------------------------------------------
# propagation: equal to the hand-computed +-1 sigma refit


def test_mass_err_systematic_equals_the_refit_by_hand(tmp_path):
    impacts = EX / "maple_impacts.csv"
    sigma = 0.31
    with_err = _write(tmp_path / "err.csv", MAPLE_HEAD + ",M_oz_err", MAPLE_ROW.format(M=31.0, I0=2480) + f",{sigma}")
    c = _chain(impacts, with_err)
    fit = c.fit_ex
    assert list(fit["systematic"].values) == ["bat:maple:M_oz"]
    assert float(fit["systematic_rel_sigma"][0]) == pytest.approx(sigma / 31.0)
    hand = {}
    for side in (1, -1):
        moved = _write(tmp_path / f"m{side}.csv", MAPLE_HEAD, MAPLE_ROW.format(M=31.0 + side * sigma, I0=2480))
        hand[side] = _chain(impacts, moved).fit_ex
    for q in ("e_x", "e_x_pooled", "e_y_implied"):
        expect = 0.5 * np.abs(hand[1][q].values - hand[-1][q].values)
        got = fit[f"{q}_syst_by_source"].values[0]
        ok = np.isfinite(expect)
        # the same arithmetic in another order (shifted r_x against r_x of the moved table): 1e-12 relative
        assert np.allclose(got[ok], expect[ok], rtol=1e-9, atol=1e-15), q
        assert np.all(expect[ok] > 0), q
        assert np.allclose(fit[f"{q}_syst"].values[ok], got[ok])
    # e_x's statistical error is as without the column: the systematic is apart from it
    plain = _chain(impacts, EX / "maple_bats.csv").fit_ex
    assert np.array_equal(plain["e_x"].values, fit["e_x"].values, equal_nan=True)
    assert np.array_equal(plain["e_x_err"].values, fit["e_x_err"].values, equal_nan=True)
    assert "systematic" not in plain.coords


def test_lab_balance_point_systematic_equals_the_refit_by_hand(tmp_path):
    impacts = EX / "hickory_impacts.csv"
    sigma = 0.1
    row = HICKORY_ROW.format(w=32, bp=23.0, moi=11200) + f",{sigma}"
    c = _chain(impacts, _write(tmp_path / "h.csv", HICKORY_HEAD + ",balance_in_err", row))
    hand = [
        _chain(
            impacts,
            _write(tmp_path / f"h{s}.csv", HICKORY_HEAD, HICKORY_ROW.format(w=32, bp=23.0 + s * sigma, moi=11200)),
        ).fit_ex
        for s in (1, -1)
    ]
    expect = 0.5 * np.abs(hand[0]["e_x"].values - hand[1]["e_x"].values)
    got = c.fit_ex["e_x_syst_by_source"].sel(systematic="bat:hickory:balance_in").values
    ok = np.isfinite(expect)
    assert ok.any() and np.allclose(got[ok], expect[ok], rtol=1e-9)
    # a first-order expectation: e_x depends on the bat through r_x alone, so the shift is
    # d e_x / d r_x times the change of r_x; (1 + e_x)(1 + r_x) is what the spin fit measures
    rec = c.reconstruct
    src = "bat:hickory:balance_in"
    for ball in c.fit_ex["ball"].values.astype(str):
        mine = rec["ball"].values.astype(str) == ball
        per = rec["r_x_shift"].sel(systematic=src).values[:, mine]
        d_rx = 0.5 * (per[0] - per[1])  # half of (+1 sigma) - (-1 sigma)
        r_x = rec["r_x"].values[mine]
        assert np.ptp(r_x) == 0 and np.ptp(d_rx) == 0  # one bat, one ball: one r_x, one shift
        e_x = float(c.fit_ex["e_x"].sel(ball=ball, bat="hickory"))
        if not math.isfinite(e_x):
            continue
        expect = abs((1 + e_x) * d_rx[0] / (1 + r_x[0]))
        # first order in d r_x (relative change ~1e-3), and the fit's weights move a little: 2 %
        assert float(c.fit_ex["e_x_syst_by_source"].sel(systematic=src, ball=ball, bat="hickory")) == pytest.approx(
            expect, rel=0.02
        )


def test_property_source_appended_to_instrument_sources(tmp_path):
    """One dataset, both kinds: the instruments' sources first, the bat's appended; each refitted alone."""
    impacts = EX / "maple_impacts.csv"
    bats = _write(tmp_path / "err.csv", MAPLE_HEAD + ",I0_oz_in2_err", MAPLE_ROW.format(M=31.0, I0=2480) + ",25")
    settings = chain.schema_settings({"impacts": str(impacts), "bats": str(bats)}, "lab")
    ds = chain.ingest(impacts, BALLS, bats, {"spin_scale_pct": 1.0})
    both = chain.run(settings, ds, load_balls(BALLS), load_bats(bats)).fit_ex
    alone = _chain(impacts, bats).fit_ex
    assert list(both["systematic"].values) == ["spin_scale", "bat:maple:I0_oz_in2"]
    a = both["e_x_syst_by_source"].sel(systematic="bat:maple:I0_oz_in2").values
    b = alone["e_x_syst_by_source"].sel(systematic="bat:maple:I0_oz_in2").values
    assert np.allclose(a, b, equal_nan=True, rtol=1e-12)
    s = both["e_x_syst_by_source"].values
    assert np.allclose(both["e_x_syst"].values, np.sqrt((s**2).sum(axis=0)), equal_nan=True)
    assert "bat maple's I0_oz_in2 = 2480 +- 25" in both["systematic"].attrs["long_name"]


def test_eta2_gets_the_property_systematic(tmp_path):
    from ballbat.stages import stronge

    impacts = EX / "maple_impacts.csv"
    bats = _write(tmp_path / "err.csv", MAPLE_HEAD + ",M_oz_err", MAPLE_ROW.format(M=31.0, I0=2480) + ",0.31")
    rec = _chain(impacts, bats).reconstruct
    from ballbat.pipeline.config import checked_block

    settings = stronge.StrongeSettings.from_config({"stronge": checked_block({}, "stronge")})
    st = stronge.run(settings, rec)
    per = st["eta2_syst_by_source"].sel(systematic="bat:maple:M_oz").values
    assert np.all(np.isfinite(per[np.isfinite(st["eta2"].values)])) and np.nanmax(per) > 0
    assert math.isfinite(float(np.nanmax(st["eta2_syst"].values)))


# ---------------------------------------------------------------------------------------
# replicate studies that draw the bat's properties (docs/studies.md)


def _study(tmp_path):
    import yaml

    from ballbat.config_checks import validate_config
    from ballbat.studies.settings import StudySettings

    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    over = yaml.safe_load((EX / "property_study.yaml").read_text())
    ds = over["datasets"]["hickory_study"]
    ds["synthetic"]["impacts"] = {"baseball": {"hickory": 40}, "softball": {"hickory": 40}}  # small and quick
    ds["bats"] = str(EX / "property_study_bats.csv")
    base["datasets"].update(over["datasets"])
    base["studies"].update(over["studies"])
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    return StudySettings.from_config(validate_config(base, schema), "properties")


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


def test_study_replicate_draws_and_its_systematic_is_the_finite_difference(tmp_path):
    """One replicate: its truth is its drawn bat's, its systematic the +-1 sigma refit's, its effect first order."""
    from dataclasses import replace

    from ballbat.studies.replicates import _truth_source, chain_settings, drawn_tables, replicate_seeds, run_replicate

    st = _study(tmp_path)
    bats, balls = load_bats(EX / "property_study_bats.csv"), load_balls(BALLS)
    dataset = st.point_dataset(0)
    rows = {(r["quantity"], r["ball"], r["bat"]): r for r in run_replicate(st, dataset, 3, balls, bats)}
    # the same draw, by hand
    true_balls, true_bats, z = drawn_tables(st, 3, balls, bats)
    assert true_bats["hickory"].M != bats["hickory"].M and set(z) == {
        f"bat:hickory:{c}" for c in ("balance_in", "impact_from_tip_in", "moi_oz_in2", "weight_oz")
    }
    seeds = replicate_seeds(st.seed, 3)
    cs = chain_settings(st, dataset, seeds)
    src = chain.source(cs, true_balls, true_bats)
    quiet = replace(cs, fit_ex=replace(cs.fit_ex, systematic=False))
    # finite differences: the sheet with one value moved by +-sigma, every other as the sheet says
    row = {"length_in": 34, "weight_oz": 32, "balance_in": 23.0, "pivot_in": 6, "moi_oz_in2": 11200}
    row |= {"impact_from_tip_in": 6, "diameter_in": 2.6, "Iz_oz_in2": 11.0}
    sig = {"balance_in": 0.1, "impact_from_tip_in": 0.25, "moi_oz_in2": 336.0, "weight_oz": 0.1}
    parts, effect = [], 0.0
    from ballbat.properties import _bat_from_paper_row

    for col, s in sorted(sig.items()):
        e = []
        for side in (1, -1):
            moved = {"hickory": _bat_from_paper_row(bats["hickory"], batlab.moved_row(row, {col: side * s}, "lab"))}
            e.append(float(chain.run(quiet, src, balls, moved).fit_ex["e_x"].sel(ball="baseball", bat="hickory")))
        parts.append(0.5 * (e[0] - e[1]))
        effect += z[f"bat:hickory:{col}"] * parts[-1]
    r = rows[("e_x", "baseball", "hickory")]
    assert r["systematic"] == pytest.approx(float(np.sqrt(np.sum(np.square(parts)))), rel=1e-9)
    assert r["systematic"] > 0.3 * r["uncertainty"]  # of the size the study is for: not negligible
    assert r["calibration_effect"] == pytest.approx(effect, rel=1e-9)
    # the truth: the estimator on the noise-free values with the true bat (the drawn one), near the bat's e_x
    truth = chain.run(quiet, _truth_source(src), true_balls, true_bats).fit_ex
    assert r["truth"] == pytest.approx(float(truth["e_x"].sel(ball="baseball", bat="hickory")), rel=1e-12)
    assert r["truth"] == pytest.approx(0.455, abs=0.002)
    # analysed with the sheet, value + effect is, to first order, the analysis with the true bat
    with_true = float(chain.run(quiet, src, true_balls, true_bats).fit_ex["e_x"].sel(ball="baseball", bat="hickory"))
    assert r["value"] + r["calibration_effect"] == pytest.approx(with_true, abs=0.1 * r["systematic"])
