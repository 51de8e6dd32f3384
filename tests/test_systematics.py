"""Systematics (ballbat.systematics): every stated calibration and property uncertainty to every reported
quantity, each the fits again at +-1 sigma (issues 22, 35).
"""

from __future__ import annotations

import csv
import functools
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from helpers import BALLS, BATS, HICKORY_HEAD, experiment, render, render_cfg
from helpers import reduce_tracks_of as reduce
from helpers import write_table as _write

from ballbat import batlab, systematics
from ballbat import chain as chain_instrument_calibration
from ballbat import chain as chain_property_systematics
from ballbat.compare import NO_SYSTEMATIC_NOTE, SYSTEMATIC_NOTE, systematic_note
from ballbat.pipeline.config import checked_block
from ballbat.properties import load_balls, load_bats
from ballbat.stages import fit_ex, normalize, reconstruct, stronge
from ballbat.stages import reduce as reduce_stage
from ballbat.stages.fit_ex import FIT_FAMILIES
from ballbat.stages.reduce import reduction_dataset
from ballbat.tracks.data import camera_block

STRONGE = {
    "e_y": 0.5,
    "mu": 0.5,
    "psi_grid_deg": {"start": 0, "stop": 60, "num": 7},
    "psi_history_deg": 30,
    "n_time": 20,
}
SOURCE = list(systematics.SOURCES)
FIT_SETTINGS = fit_ex.FitExSettings(0.5, systematic=True, check_physical=True, mu_k_bound=True)  # as the workflow's


@functools.cache
def chain(swing=(), spin=(), rig=(), vary_e_y=False):
    """Reduce (with shifts), reconstruct and fit one rendered experiment; settings as sorted tuples."""
    ds = experiment(11, per_bat=12)
    cfg = render_cfg(swing=dict(swing), spin=dict(spin))
    cfg["rig"].update(dict(rig))
    tr, _ = render(ds, cfg, {k: ds[f"truth_{k}"].values for k in ("e_x", "e_y")})
    settings = reduce_stage.ReduceSettings.from_config(
        camera_block(checked_block(cfg, "render")), "test", systematics=True
    )
    red, _ = reduce_stage.reduce_and_check(settings, tr, BALLS, BATS)
    rec = reconstruct.run(
        reconstruct.ReconstructSettings(),
        normalize.run(normalize.NormalizeSettings(77.0), reduction_dataset(red)),
        BALLS,
        BATS,
    )
    fit = fit_ex.run(FIT_SETTINGS, rec)
    st = stronge.run(stronge.StrongeSettings(vary_e_y=vary_e_y, vary_mu=False, **STRONGE), rec)
    return rec, fit, st


def by(ds, q, source):
    return ds[f"{q}_syst_by_source"].sel(systematic=source).values


def finite(ds, q):
    return np.isfinite(ds[q].values)


def test_frame_rate_alone_reaches_every_quantity():
    """Only the swing camera's fps_err: a systematic on every quantity, none from the pixel scales."""
    rec, fit, st = chain(swing=(("fps_err", 0.002),))
    assert rec["systematic_rel_sigma"].sel(systematic="swing_fps") == 0.002
    for k in systematics.SHIFTED:  # reduced again at +-1 sigma of that source only
        shifts = rec[f"{k}_shift"]
        assert np.all(shifts.sel(systematic=[s for s in SOURCE if s != "swing_fps"]).values == 0), k
    assert np.abs(rec["v_bat_shift"].sel(systematic="swing_fps").values).max() > 0
    for q in systematics.FIT_QUANTITIES:
        ok = finite(fit, q)
        assert ok.any(), q
        assert np.all(by(fit, q, "swing_fps")[ok] > 0), q
        for s in ("swing_m_per_px", "spin_m_per_px"):
            np.testing.assert_array_equal(by(fit, q, s)[ok], 0.0, err_msg=f"{q} {s}")
        assert np.all(np.isnan(fit[f"{q}_syst"].values[~ok]))  # no value, no systematic
    np.testing.assert_array_equal(fit["e_x_err_scale"].values[finite(fit, "e_x")], 0.0)
    assert np.all(by(st, "eta2", "swing_fps") > 0)
    np.testing.assert_array_equal(by(st, "eta2", "swing_m_per_px"), 0.0)


@pytest.mark.parametrize("key", ["fps_err", "m_per_px_err"])
def test_doubling_a_sigma_doubles_its_systematic(key):
    """Linear regime: twice the stated uncertainty, twice the systematic (e_x per bat and pooled, eta^2)."""
    source = "swing_fps" if key == "fps_err" else "swing_m_per_px"
    _, f1, s1 = chain(swing=((key, 0.002),))
    _, f2, s2 = chain(swing=((key, 0.004),))
    for q in ("e_x", "e_x_pooled"):
        ok = finite(f1, q)
        np.testing.assert_allclose(by(f2, q, source)[ok], 2 * by(f1, q, source)[ok], rtol=0.05, err_msg=q)
    np.testing.assert_allclose(by(s2, "eta2", source), 2 * by(s1, "eta2", source), rtol=0.05)


@pytest.mark.slow  # more than 2 s
def test_combined_is_the_quadrature_of_the_sources_and_total_adds_the_statistical():
    """Several sources at once: <q>_syst is their quadrature sum, <q>_err_total adds the standard error."""
    rec, fit, st = chain(
        swing=(("m_per_px_err", 0.005),),
        spin=(("fps_err", 0.002), ("m_per_px_err", 0.005)),
        rig=(("pivot_to_impact_err_in", 0.05), ("pivot_to_tip_err_in", 0.1)),
    )
    assert np.all(rec["systematic_rel_sigma"].sel(systematic="swing_fps").values == 0)
    for ds, names in ((fit, systematics.FIT_QUANTITIES), (st, ("eta2",))):
        for q in names:
            ok = finite(ds, q)
            per = ds[f"{q}_syst_by_source"].values[:, ok]
            np.testing.assert_allclose(ds[f"{q}_syst"].values[ok], np.sqrt(np.sum(per**2, axis=0)), rtol=1e-12)
            np.testing.assert_array_equal(by(ds, q, "swing_fps")[ok], 0.0)
            if f"{q}_err" in ds:
                np.testing.assert_allclose(
                    ds[f"{q}_err_total"].values[ok], np.hypot(ds[f"{q}_err"].values[ok], ds[f"{q}_syst"].values[ok])
                )
    # what each source moves: v_bat (and so e_x) with the rig's impact distance, spin only with the spin fps
    ok = finite(fit, "e_x")
    assert np.all(by(fit, "e_x", "pivot_to_impact")[ok] > 0)
    np.testing.assert_array_equal(rec["v_ball_shift"].sel(systematic="pivot_to_impact").values, 0.0)
    assert np.abs(rec["omega_shift"].sel(systematic="spin_fps").values).max() > 0
    np.testing.assert_array_equal(rec["omega_shift"].sel(systematic="swing_m_per_px").values, 0.0)
    # pivot_to_impact scales v_bat exactly: its shift is v_bat x the relative sigma
    rel = 0.05 / 28.0
    v = rec["v_bat"].values
    up = rec["v_bat_shift"].sel(systematic="pivot_to_impact", shift=1).values
    np.testing.assert_allclose(up[np.isfinite(v)], rel * v[np.isfinite(v)], rtol=1e-9)


def test_swing_scale_systematic_of_e_x_against_the_linear_rescale():
    """The exact rerun's e_x_err_scale against the former linear rescale of v_bat and v_ball.

    The rerun is larger by a few per cent: the tip circle's radius is the rig's (metres, not
    pixels), so v_bat moves by about 1.02 x the scale's change, and the flight fit's gravity
    term and theta move a little. Measured on the default run: +2.8 to +4.2 %.
    """
    from ballbat.fitting import analyze_impacts

    rec, fit, _ = chain(swing=(("m_per_px_err", 0.005),))
    legacy = rec.drop_vars([v for v in rec.data_vars if v.endswith("_shift")] + ["systematic_rel_sigma"])
    old = analyze_impacts(legacy, 0.5).systematic
    assert set(old) == {"e_x_err_scale", "e_x_pooled_err_scale"}
    for k in old:
        ok = np.isfinite(old[k])
        ratio = fit[k].values[ok] / old[k][ok]
        assert np.all((ratio > 1.0) & (ratio < 1.08)), (k, ratio)
    np.testing.assert_array_equal(fit["e_x_err_scale"].values, by(fit, "e_x", "swing_m_per_px"))


def test_no_shifts_no_systematics():
    """Impacts without shifts (direct-noise synthetic data, a measured file): no systematic variables."""
    rec, _, _ = chain(swing=(("fps_err", 0.002),))
    bare = rec.drop_vars(
        [v for v in rec.data_vars if v.endswith("_shift")]
        + ["systematic_rel_sigma", "v_bat_err_scale", "v_ball_err_scale"]
    )
    fit = fit_ex.run(FIT_SETTINGS, bare)
    st = stronge.run(stronge.StrongeSettings(vary_e_y=False, vary_mu=False, **STRONGE), bare)
    for ds in (fit, st):
        assert not [v for v in ds.data_vars if "syst" in v or "err_scale" in v]


@pytest.mark.slow  # about 2 s: a whole chain reduced again at +-1 sigma
def test_fitted_e_y_gets_a_systematic():
    """With e_y fitted beside eta^2, e_y gets its systematic too."""
    _, _, st = chain(swing=(("fps_err", 0.002),), vary_e_y=True)
    assert np.all(by(st, "e_y", "swing_fps") > 0)
    assert "mu_syst" not in st


def test_every_fit_family_is_covered():
    """Every line-fit family of fit_ex.nc is a quantity with systematics."""
    assert set(FIT_FAMILIES) <= set(systematics.FIT_QUANTITIES)


def test_tables_carry_the_systematics(tmp_path):
    """The comparison rows have a systematic for every quantity that has one; the workbook has stat, syst
    and total columns for every estimate and a sheet of each source's part.
    """
    import openpyxl

    from ballbat.compare import comparison_table, fit_rows, stronge_rows
    from ballbat.workbook import dataset_workbook

    rec, fit, st = chain(swing=(("m_per_px_err", 0.005),), spin=(("fps_err", 0.002),))
    rows = fit_rows(fit) + stronge_rows(st)
    with_syst = {r["quantity"] for r in rows if r.get("systematic") is not None}
    assert with_syst == {*systematics.FIT_QUANTITIES, "eta2"} - {
        "spin_theta_slope_intercept",
        "speed_theta_slope_intercept",
    }  # the comparison table has no intercepts
    row = next(r for r in rows if r["quantity"] == "e_x_pooled" and r["ball"] == "softball")
    assert row["systematic"] == pytest.approx(float(fit.e_x_pooled_syst.sel(ball="softball")))
    row = next(r for r in rows if r["quantity"] == "spin_theta_slope" and r["ball"] == "baseball")
    assert row["systematic"] == pytest.approx(
        float(fit.spin_theta_slope_syst.sel(ball="baseball")) * 60 / (2 * np.pi) * np.pi / 180
    )
    table = comparison_table(rows)
    path = tmp_path / "results.xlsx"
    dataset_workbook(path, rec, fit, st, [{k: r[k] for k in ("quantity", "value")} for r in table])
    book = openpyxl.load_workbook(path)
    sec4 = [c.value for c in book["sec4"][1]]
    for q in ("tan_ratio_slope", "e_y_implied", "mu_k_lower_bound", "spin_theta_slope", "speed_theta_slope"):
        i = sec4.index(q)
        assert sec4[i : i + 4] == [q, f"{q}_err", f"{q}_syst", f"{q}_err_total"], sec4
    assert "gross_slip_psi_syst" in sec4 and "spin_theta_slope_intercept_syst" in sec4
    eta2 = [c.value for c in book["eta2"][1]]
    assert eta2[1:5] == ["eta2", "eta2_err", "eta2_syst", "eta2_err_total"]
    assert [c.value for c in book["e_x"][1]][2:6] == ["e_x", "e_x_err", "e_x_syst", "e_x_err_total"]
    per = list(book["systematics"].iter_rows(min_row=3, values_only=True))
    sources = {r[3] for r in per}
    assert sources == {"swing_m_per_px", "spin_fps"}  # sources with a stated uncertainty only
    got = {(r[0], r[1], r[2] or "", r[3]): r[5] for r in per}  # an empty cell reads back as None
    assert got[("eta2", "baseball", "", "spin_fps")] == pytest.approx(
        float(st.eta2_syst_by_source.sel(ball="baseball", systematic="spin_fps"))
    )
    assert got[("e_x", "baseball", "wood", "swing_m_per_px")] == pytest.approx(
        float(fit.e_x_err_scale.sel(ball="baseball", bat="wood"))
    )


ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "config" / "examples"
IMPACTS, BATS_instrument_calibration, BALLS_instrument_calibration = (
    EX / "maple_impacts.csv",
    EX / "maple_bats.csv",
    ROOT / "config" / "balls.csv",
)


def _fit(impacts: Path, calibration: dict | None = None):
    settings = chain_instrument_calibration.schema_settings(
        {"impacts": str(impacts), "bats": str(BATS_instrument_calibration)}, "maple"
    )
    ds = chain_instrument_calibration.ingest(
        impacts, BALLS_instrument_calibration, BATS_instrument_calibration, calibration
    )
    return chain_instrument_calibration.run(
        settings, ds, load_balls(BALLS_instrument_calibration), load_bats(BATS_instrument_calibration)
    ).fit_ex


def _moved(tmp_path: Path, columns: tuple[str, ...], factor: float = 1.0, offset: float = 0.0) -> Path:
    """The impacts file with ``columns`` times ``factor`` plus ``offset`` (what a miscalibrated instrument gives)."""
    with IMPACTS.open() as fh:
        rows = list(csv.DictReader(fh))
    for row in rows:
        for c in columns:
            if row[c] != "":
                row[c] = repr(float(row[c]) * factor + offset)
    out = tmp_path / f"moved_{'_'.join(columns)}_{factor}_{offset}.csv"
    with out.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return out


@pytest.fixture(scope="module")
def nominal():
    return _fit(IMPACTS)


CASES = {
    # source: (config, columns moved by hand, factor at +1 sigma, offset at +1 sigma)
    # (a scale moves the file's standard uncertainties of those values with them; an offset does not)
    "speed_scale": (
        {"speed_scale_pct": 1.0},
        ("v_bat_mph", "v_ball_mph", "v_bat_mph_err", "v_ball_mph_err"),
        0.01,
        0.0,
    ),
    "spin_scale": ({"spin_scale_pct": 0.5}, ("omega_rpm", "omega_rpm_err"), 0.005, 0.0),
    "angle_offset": ({"angle_offset_deg": 0.2}, ("theta_deg",), 0.0, 0.2),
}


@pytest.mark.parametrize("source", list(CASES))
def test_calibration_systematic_is_the_rescaled_file_refitted(tmp_path, nominal, source):
    """Speed scale 1 %: e_x's systematic is half of what rescaling every speed by +-1 % does to it; alike the others."""
    cal, columns, rel, off = CASES[source]
    fit = _fit(IMPACTS, cal)
    assert list(fit["systematic"].values) == [source]
    got = fit["e_x_syst_by_source"].sel(systematic=source).values
    plus = _fit(_moved(tmp_path, columns, 1 + rel, off))
    minus = _fit(_moved(tmp_path, columns, 1 - rel, -off))
    for q in ("e_x", "e_x_pooled", "tan_ratio_slope", "e_y_implied"):
        expect = 0.5 * np.abs(plus[q].values - minus[q].values)
        ok = np.isfinite(expect)
        # the file holds mph, deg and rpm to its own digits; the hand-moved file is written back with
        # repr, so the two agree to rounding (1e-9 relative) rather than bit for bit
        assert np.allclose(fit[f"{q}_syst_by_source"].values[0][ok], expect[ok], rtol=1e-6, atol=1e-12), q
    assert np.all(got[np.isfinite(got)] > 0)
    # the nominal numbers do not move; the systematic stands apart from the standard error
    assert np.array_equal(fit["e_x"].values, nominal["e_x"].values, equal_nan=True)
    assert np.array_equal(fit["e_x_err"].values, nominal["e_x_err"].values, equal_nan=True)
    assert np.allclose(fit["e_x_err_total"].values, np.hypot(fit["e_x_err"].values, got), equal_nan=True)


def test_speed_scale_size_and_direction(nominal):
    """A larger speed scale uncertainty gives a proportionally larger systematic (linear for small sigma)."""
    one = _fit(IMPACTS, {"speed_scale_pct": 1.0})["e_x_pooled_syst"].values
    two = _fit(IMPACTS, {"speed_scale_pct": 2.0})["e_x_pooled_syst"].values
    ok = np.isfinite(one)
    assert ok.any() and np.allclose(two[ok] / one[ok], 2.0, rtol=0.01)
    # size: both speeds scale, so the normalised spin's bracket (v_bat sin psi) scales by the same 1 %,
    # and psi moves a little with v_ball: 1 + e_x changes by about 1 %, i.e. e_x by about (1 + e_x) x 1 %
    e_x = nominal["e_x_pooled"].values[ok]
    assert np.allclose(one[ok], 0.01 * (1 + e_x), rtol=0.5)


def test_nothing_stated_no_source_and_the_text_says_so(nominal):
    from ballbat.reporting import fig5_numbers

    assert "systematic" not in nominal.coords and "e_x_syst" not in nominal
    assert systematic_note(nominal) == NO_SYSTEMATIC_NOTE
    assert "no calibration uncertainty stated" in NO_SYSTEMATIC_NOTE
    settings = chain_instrument_calibration.schema_settings(
        {"impacts": str(IMPACTS), "bats": str(BATS_instrument_calibration)}, "maple"
    )
    impacts = chain_instrument_calibration.reconstructed(
        settings,
        chain_instrument_calibration.ingest(IMPACTS, BALLS_instrument_calibration, BATS_instrument_calibration),
        load_balls(BALLS_instrument_calibration),
        load_bats(BATS_instrument_calibration),
    )
    assert f"syst. —: {NO_SYSTEMATIC_NOTE}" in fig5_numbers(impacts, nominal)
    stated = _fit(IMPACTS, {"spin_scale_pct": 1.0})
    text = fig5_numbers(impacts, stated)
    assert "syst. —" not in text and "the instruments' calibrations" in text and "spin_scale" in text
    assert "(stat) ±" in text and "(syst)" in text


def test_front_page_and_summary_split_by_source(tmp_path, nominal):
    from ballbat.frontpage import dataset_section
    from ballbat.pipeline.config import checked_block
    from ballbat.stages import stronge

    settings = chain_instrument_calibration.schema_settings(
        {"impacts": str(IMPACTS), "bats": str(BATS_instrument_calibration)}, "maple"
    )
    c = chain_instrument_calibration.run(
        settings,
        chain_instrument_calibration.ingest(
            IMPACTS,
            BALLS_instrument_calibration,
            BATS_instrument_calibration,
            {"speed_scale_pct": 1.0, "angle_offset_deg": 0.2},
        ),
        load_balls(BALLS_instrument_calibration),
        load_bats(BATS_instrument_calibration),
    )
    st = stronge.run(stronge.StrongeSettings.from_config({"stronge": checked_block({}, "stronge")}), c.reconstruct)
    page = "\n".join(dataset_section("maple", c.fit_ex, st))
    assert "syst. —" not in page and "By source, pooled e_x of the baseball: " in page
    assert "speed\\_scale" in page and "angle\\_offset" in page  # (escaped for reStructuredText)
    plain = "\n".join(dataset_section("maple", nominal, st))
    assert f"syst. —: {NO_SYSTEMATIC_NOTE}" in plain
    # camera-tracked data alone keeps its note as it was
    assert SYSTEMATIC_NOTE.startswith("every stated calibration uncertainty (pixel scale")


def test_workbook_lists_each_source_or_says_none(tmp_path, nominal):
    from openpyxl import load_workbook

    from ballbat.pipeline.config import checked_block
    from ballbat.stages import stronge
    from ballbat.workbook import dataset_workbook

    settings = chain_instrument_calibration.schema_settings(
        {"impacts": str(IMPACTS), "bats": str(BATS_instrument_calibration)}, "maple"
    )
    sst = stronge.StrongeSettings.from_config({"stronge": checked_block({}, "stronge")})
    for cal, name in (({"angle_offset_deg": 0.2}, "with.xlsx"), (None, "without.xlsx")):
        c = chain_instrument_calibration.run(
            settings,
            chain_instrument_calibration.ingest(
                IMPACTS, BALLS_instrument_calibration, BATS_instrument_calibration, cal
            ),
            load_balls(BALLS_instrument_calibration),
            load_bats(BATS_instrument_calibration),
        )
        dataset_workbook(tmp_path / name, c.reconstruct, c.fit_ex, stronge.run(sst, c.reconstruct), [])
    rows = list(load_workbook(tmp_path / "with.xlsx")["systematics"].iter_rows(min_row=3, values_only=True))
    e_x = [r for r in rows if r[0] == "e_x_pooled"]
    assert e_x and all(r[3] == "angle_offset" and r[4] is None and r[5] > 0 for r in e_x)
    sheet = load_workbook(tmp_path / "with.xlsx")["e_x"]
    assert [c.value for c in sheet[1]][4] == "e_x_syst" and all(
        r[4] for r in sheet.iter_rows(min_row=3, values_only=True)
    )
    none = list(load_workbook(tmp_path / "without.xlsx")["systematics"].iter_rows(min_row=3, values_only=True))
    assert none == [("e_x", None, None, "none stated", None, None, NO_SYSTEMATIC_NOTE)]


BALLS_property_systematics = ROOT / "config" / "balls.csv"
MAPLE_HEAD = "bat,name,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in"
MAPLE_ROW = "maple,maple,{M},{I0},9.6,6.5,1.24"
HICKORY_ROW = "hickory,hickory,lab,34,{w},{bp},6,{moi},6,2.6,11.0"


def _chain(impacts: Path, bats: Path, balls: Path = BALLS_property_systematics):
    settings = chain_property_systematics.schema_settings({"impacts": str(impacts), "bats": str(bats)}, "lab")
    ds = chain_property_systematics.ingest(impacts, balls, bats)
    return chain_property_systematics.run(settings, ds, load_balls(balls), load_bats(bats))


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
    settings = chain_property_systematics.schema_settings({"impacts": str(impacts), "bats": str(bats)}, "lab")
    ds = chain_property_systematics.ingest(impacts, BALLS_property_systematics, bats, {"spin_scale_pct": 1.0})
    both = chain_property_systematics.run(settings, ds, load_balls(BALLS_property_systematics), load_bats(bats)).fit_ex
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


@pytest.mark.slow  # more than 2 s
def test_study_replicate_draws_and_its_systematic_is_the_finite_difference(tmp_path):
    """One replicate: its truth is its drawn bat's, its systematic the +-1 sigma refit's, its effect first order."""
    from dataclasses import replace

    from ballbat.studies.replicates import _truth_source, chain_settings, drawn_tables, replicate_seeds, run_replicate

    st = _study(tmp_path)
    bats, balls = load_bats(EX / "property_study_bats.csv"), load_balls(BALLS_property_systematics)
    dataset = st.point_dataset(0)
    rows = {(r["quantity"], r["ball"], r["bat"]): r for r in run_replicate(st, dataset, 3, balls, bats)}
    # the same draw, by hand
    true_balls, true_bats, z = drawn_tables(st, 3, balls, bats)
    assert true_bats["hickory"].M != bats["hickory"].M and set(z) == {
        f"bat:hickory:{c}" for c in ("balance_in", "impact_from_tip_in", "moi_oz_in2", "weight_oz")
    }
    seeds = replicate_seeds(st.seed, 3)
    cs = chain_settings(st, dataset, seeds)
    src = chain_property_systematics.source(cs, true_balls, true_bats)
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
            e.append(
                float(
                    chain_property_systematics.run(quiet, src, balls, moved)
                    .fit_ex["e_x"]
                    .sel(ball="baseball", bat="hickory")
                )
            )
        parts.append(0.5 * (e[0] - e[1]))
        effect += z[f"bat:hickory:{col}"] * parts[-1]
    r = rows[("e_x", "baseball", "hickory")]
    assert r["systematic"] == pytest.approx(float(np.sqrt(np.sum(np.square(parts)))), rel=1e-9)
    assert r["systematic"] > 0.3 * r["uncertainty"]  # of the size the study is for: not negligible
    assert r["calibration_effect"] == pytest.approx(effect, rel=1e-9)
    # the truth: the estimator on the noise-free values with the true bat (the drawn one), near the bat's e_x
    truth = chain_property_systematics.run(quiet, _truth_source(src), true_balls, true_bats).fit_ex
    assert r["truth"] == pytest.approx(float(truth["e_x"].sel(ball="baseball", bat="hickory")), rel=1e-12)
    assert r["truth"] == pytest.approx(0.455, abs=0.002)
    # analysed with the sheet, value + effect is, to first order, the analysis with the true bat
    with_true = float(
        chain_property_systematics.run(quiet, src, true_balls, true_bats)
        .fit_ex["e_x"]
        .sel(ball="baseball", bat="hickory")
    )
    assert r["value"] + r["calibration_effect"] == pytest.approx(with_true, abs=0.1 * r["systematic"])


def test_pixel_scale_systematic_reaches_e_x():
    """m_per_px_err gives e_x a systematic error: the shift of e_x when the scale is off by that much."""
    from ballbat.stages import fit_ex, normalize, reconstruct

    ds = experiment(11, per_bat=20)

    def fit(rel, scale=1.0):
        truth = {k: ds[f"truth_{k}"].values for k in ("e_x", "e_y")}
        tr, s = render(ds, render_cfg(swing={"m_per_px_err": rel}), truth)
        # both cameras' scales off alike (the spin camera cross-checks the swing camera's speed)
        cam = replace(s.swing.camera, m_per_px=s.swing.camera.m_per_px * scale)
        spin = replace(s.spin.camera, m_per_px=s.spin.camera.m_per_px * scale)
        red = reduction_dataset(reduce(tr, s, swing=cam, spin=spin))
        rec = reconstruct.run(
            reconstruct.ReconstructSettings(),
            normalize.run(normalize.NormalizeSettings(v_ref_mph=77.0), red),
            BALLS,
            BATS,
        )
        return fit_ex.run(
            fit_ex.FitExSettings(mu_k_example=0.5, systematic=True, check_physical=True, mu_k_bound=True), rec
        )

    base, sys1, sys2 = fit(0.0), fit(0.01), fit(0.02)
    assert "e_x_err_scale" in sys1 and "e_x_pooled_err_scale" in sys1
    np.testing.assert_array_equal(sys1.e_x.values, base.e_x.values)  # the value is untouched
    e1, e2 = sys1.e_x_err_scale.values, sys2.e_x_err_scale.values
    ok = np.isfinite(e1)
    assert np.all(e1[ok] > 0) and np.all(np.isfinite(base.e_x_err_scale.values[ok]))
    np.testing.assert_allclose(base.e_x_err_scale.values[ok], 0.0, atol=1e-12)
    np.testing.assert_allclose(e2[ok], 2 * e1[ok], rtol=0.02)  # linear in the scale's uncertainty
    # a camera whose scale really is 1 % off moves e_x by about the stated systematic
    up, down = fit(0.0, 1.01), fit(0.0, 0.99)
    shift = 0.5 * np.abs(up.e_x.values - down.e_x.values)
    np.testing.assert_allclose(shift[ok], e1[ok], rtol=0.1)
    assert np.all(e1[ok] > base.e_x_err.values[ok] / 10)  # not negligible: 1 % of scale
