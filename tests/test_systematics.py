"""Calibration systematics (issue 22): every stated calibration uncertainty to every reported quantity.

In memory: rendered tracks reduced with their shifts (ballbat.systematics.reduce_shifts), then
normalize, reconstruct, fit_ex and the eta^2 fit, as the workflow runs them.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from helpers import BALLS, BATS, experiment, render, render_cfg

from ballbat import systematics
from ballbat.pipeline.config import checked_block
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
FIT_SETTINGS = fit_ex.FitExSettings(0.5, systematic=True, check_physical=True)  # as the workflow's


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
