"""Figures and report text, from small fake datasets (the workflow's figures: workflow/test_outputs.py)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from PIL import Image

from ballbat import plotting
from ballbat.pipeline.ncio import write_dataset
from ballbat.pipeline.products import build_dataset
from ballbat.stages.stronge import STRONGE_COORDS, stronge_variables
from ballbat.stronge.analysis import PUBLISHED_ETA2
from ballbat.stronge.regimes import Regime
from workflow_helpers import assert_not_blank

BALLS = ["baseball", "softball"]


def fake_stronge() -> xr.Dataset:
    """Made-up values in the declared layout of results/{dataset}/stronge.nc.

    The layout is the package's own table (``stronge_variables``, ``STRONGE_COORDS``) and
    ``build_dataset`` refuses values that miss or add a variable, so the fake cannot drift
    from the file the workflow writes.
    """
    psi = np.radians(np.linspace(0.0, 85.0, 86))
    r_x = np.array([0.12, 0.10])[:, None]
    eta2 = np.array([4.9, 6.1])
    vtf_x = np.tan(psi)[None, :] / (1 + r_x)
    e_x = np.array([0.40, 0.15])[:, None] * np.clip(1.2 - psi[None, :] / np.radians(60), 0, 1)
    e_x_pub = e_x * 1.03
    rng = np.random.default_rng(1)
    n = [30, 25]
    data_ball = np.repeat(BALLS, n)
    psi_d = np.concatenate([rng.uniform(0, np.radians(30), n[0]), rng.uniform(0, np.radians(41), n[1])])
    k = (data_ball == "softball").astype(int)
    data_x = np.tan(psi_d) / (1 + r_x[k, 0])
    data_y = (1 + np.array([0.40, 0.15])[k]) * data_x + rng.normal(0, 0.01, psi_d.size)
    t = np.linspace(0.0, 1.7, 171)
    n_force = np.where(t <= 1.5, np.sin(np.pi * np.clip(t, 0, 1.5) / 1.5), np.nan)
    stick = np.where(t < 1.4, 1.0, np.where(t <= 1.5, 0.0, np.nan))
    tb = np.stack([t, t])
    two = np.ones(2)
    values = {
        "eta2": eta2,
        "eta2_err": [0.2, 0.3],
        "eta2_ci_low": eta2 - 0.4,
        "eta2_ci_high": eta2 + 0.4,
        "eta2_n": n,
        "eta2_redchi": [1.1, 0.9],
        "eta2_dof": [21.5, 25.0],
        "eta2_published": [PUBLISHED_ETA2[b] for b in BALLS],
        "e_y": 0.5 * two,
        "e_y_err": np.nan * two,
        "mu": 0.5 * two,
        "mu_err": np.nan * two,
        "omega_ratio": [0.85, 0.76],
        "omega_ratio_bat": [0.88, 0.79],
        "r_x_mean": r_x[:, 0],
        "r_y_mean": [0.05, 0.04],
        "psi_stick_boundary": np.radians([22.0, 25.0]),
        "psi_gross_slip_boundary": np.radians([58.0, 62.0]),
        "psi_stick_paper": np.radians([67.0, 72.0]),
        "psi_gross_slip_paper": np.radians([69.0, 69.0]),
        "t_stick_end": [1.4, 1.4],
        "t_separation": [1.5, 1.5],
        "t_stretch_max": [1.16, 1.33],
        "regime_history": np.array([Regime.STICK_SLIP] * 2, dtype=np.int8),
        "n_phases_history": [2, 2],
        "vtf_x_model": vtf_x,
        "vtf_y_model": (1 + e_x) * vtf_x,
        "e_x_model": e_x,
        "vtf_y_published": (1 + e_x_pub) * vtf_x,
        "e_x_published": e_x_pub,
        "normal_force": np.stack([n_force, n_force]),
        "tangential_force": 0.3 * np.sin(2 * tb) * np.stack([n_force] * 2),
        "tangential_velocity": 0.5 * np.cos(2.5 * tb),
        "spring_stretch": np.sin(tb),
        "stick": np.stack([stick, stick]),
        "data_ball": data_ball,
        "data_vtf_x": data_x,
        "data_vtf_y": data_y,
        "data_vtf_y_err": np.full(psi_d.size, 0.01),
    }
    coords = {
        "ball": np.array(BALLS),
        "psi_grid": psi,
        "sample": np.arange(t.size),
        "t_over_tc": t,
        "impact_fit": np.arange(psi_d.size),
    }
    return build_dataset(
        stronge_variables(),
        values,
        coords={name: (var, coords[name]) for name, var in STRONGE_COORDS.items()},
        attrs={"psi_history_deg": 30.0, "frame": "bat (recoil factors r_x, r_y)"},
    )


def _lines(ax) -> dict:
    """The labelled lines of ``ax`` by label."""
    return {line.get_label(): line for line in ax.get_lines() if not line.get_label().startswith("_")}


def _xy(line) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(line.get_xdata(), dtype=float), np.asarray(line.get_ydata(), dtype=float)


def test_fig9a_draws_the_files_curves_over_the_datas_range(tmp_path):
    st = fake_stronge()
    fig = plotting.fig9a_stronge_fit(st)
    (ax,) = fig.axes
    lines = _lines(ax)
    assert set(lines) == {
        "baseball fit: η² = 4.90 ± 0.20",
        "baseball paper: η² = 4.75",
        "softball fit: η² = 6.10 ± 0.30",
        "softball paper: η² = 6.3",
    }
    for ball, fit, paper in (
        ("baseball", "fit: η² = 4.90 ± 0.20", "paper: η² = 4.75"),
        ("softball", "fit: η² = 6.10 ± 0.30", "paper: η² = 6.3"),
    ):
        s = st.sel(ball=ball)
        xmax = 1.05 * st.data_vtf_x.values[st.data_ball.values == ball].max()
        keep = s.vtf_x_model.values <= xmax  # the model over the data's range only
        assert 0 < keep.sum() < keep.size
        x, y = _xy(lines[f"{ball} {fit}"])
        np.testing.assert_array_equal(x, s.vtf_x_model.values[keep])
        np.testing.assert_array_equal(y, s.vtf_y_model.values[keep])
        np.testing.assert_array_equal(_xy(lines[f"{ball} {paper}"])[1], s.vtf_y_published.values[keep])
    # the data with their error bars, one set per ball
    bars = {c.get_label(): c for c in ax.containers}
    assert set(bars) == {"baseball data (n = 30)", "softball data (n = 25)"}
    x, y = _xy(bars["softball data (n = 25)"].lines[0])
    np.testing.assert_array_equal(x, st.data_vtf_x.values[30:])
    np.testing.assert_array_equal(y, st.data_vtf_y.values[30:])
    assert ax.get_xlim()[0] == 0 and ax.get_ylim()[0] == 0
    assert_not_blank(plotting.save_figure(fig, tmp_path / "f.png"))


def test_fig9b_extrapolates_and_marks_the_regime_boundaries(tmp_path):
    st = fake_stronge()
    fig = plotting.fig9b_stronge_extrapolation(st)
    top, bottom = fig.axes
    psi_deg = np.degrees(st.psi_grid.values)
    lines = _lines(bottom)
    for ball in BALLS:
        s = st.sel(ball=ball)
        x, y = _xy(lines[f"{ball} fit"])
        np.testing.assert_allclose(x, psi_deg, rtol=1e-12)  # the whole grid, to 85 deg
        np.testing.assert_array_equal(y, s.e_x_model.values)
        np.testing.assert_array_equal(_xy(lines[f"{ball} paper"])[1], s.e_x_published.values)
        np.testing.assert_array_equal(_xy(_lines(top)[f"{ball} fit η² = {float(s.eta2):.2f}"])[1], s.vtf_y_model.values)
    # the boundaries: a vertical line at each and its name (stick 22 and 25 deg, gross slip 58 and 62 deg)
    vertical = sorted(
        round(float(line.get_xdata()[0]), 9)
        for line in bottom.get_lines()
        if line.get_label().startswith("_") and len(set(line.get_xdata())) == 1
    )
    assert vertical == [22.0, 25.0, 58.0, 62.0]
    assert sorted((t.get_text(), round(t.get_position()[0], 9)) for t in bottom.texts) == [
        (" gross slip (baseball)", 58.0),
        (" gross slip (softball)", 62.0),
        (" stick ends (baseball)", 22.0),
        (" stick ends (softball)", 25.0),
    ]
    assert bottom.get_xlim() == (0.0, 90.0)
    assert_not_blank(plotting.save_figure(fig, tmp_path / "f.png"))


def test_fig10_draws_the_histories_and_the_stick_period(tmp_path):
    st = fake_stronge()
    fig = plotting.fig10_time_history(st)
    ax, right = fig.axes
    t = st.t_over_tc.values
    lines, points = _lines(ax), _lines(right)
    for ball in BALLS:
        s = st.sel(ball=ball)
        x, y = _xy(lines[f"{ball} N/N_max"])
        np.testing.assert_array_equal(x, t)
        np.testing.assert_array_equal(y, s.normal_force.values)
        np.testing.assert_array_equal(_xy(lines[f"{ball} F/N_max"])[1], s.tangential_force.values)
        x, y = _xy(points[f"{ball} tangential velocity"])
        np.testing.assert_array_equal(x, t[::4])  # 171 samples: every 4th, about 40 points
        np.testing.assert_array_equal(y, s.tangential_velocity.values[::4])
    # the initial stick bar of each ball: from t/t_c = 0 to 1.4 (fake: stick until 1.4)
    bars = [_xy(line) for line in ax.get_lines() if line.get_label().startswith("_")]
    assert sorted((list(x), list(np.round(y, 9))) for x, y in bars) == [
        ([0.0, pytest.approx(1.4)], [1.22, 1.22]),
        ([0.0, pytest.approx(1.4)], [1.29, 1.29]),
    ]
    assert sorted(tx.get_text().strip() for tx in ax.texts) == ["initial stick (baseball)", "initial stick (softball)"]
    assert ax.get_title() == "Fig. 10: time histories at ψ = 30° (fitted η²)"
    assert [tx.get_text() for tx in fig.legends[0].get_texts()] == [
        "baseball F/N_max",
        "baseball N/N_max",
        "softball F/N_max",
        "softball N/N_max",
        "baseball tangential velocity",
        "softball tangential velocity",
    ]
    assert_not_blank(plotting.save_figure(fig, tmp_path / "f.png"))


def test_draw_fig9_writes_pngs_and_caption_numbers(tmp_path):
    nc = write_dataset(fake_stronge(), tmp_path / "stronge.nc", title="fake", rule="test", inputs=[], config={})
    out = {"fig9a": tmp_path / "a.png", "fig9b": tmp_path / "b.png", "numbers": tmp_path / "fig9.rst"}
    plotting.draw("fig9", {"stronge": nc}, out)
    for key in ("fig9a", "fig9b"):
        assert_not_blank(out[key])
    text = out["numbers"].read_text()
    assert "baseball: η² = 4.9 ± 0.2" in text and "paper 4.75" in text
    assert "softball: η² = 6.1 ± 0.3" in text and "paper 6.3" in text
    assert "22.0°" in text and "62.0°" in text
    plotting.draw("fig10", {"stronge": nc}, {"png": tmp_path / "c.png", "numbers": tmp_path / "fig10.rst"})
    text10 = (tmp_path / "fig10.rst").read_text()
    assert "initial stick until t/t_c = 1.4" in text10 and "separation at t/t_c = 1.5" in text10
    assert "Ω_t/Ω_n = 0.85 (paper 0.86)" in text10


def test_save_figure_is_deterministic(tmp_path):
    a = plotting.save_figure(plotting.fig10_time_history(fake_stronge()), tmp_path / "a.png")
    b = plotting.save_figure(plotting.fig10_time_history(fake_stronge()), tmp_path / "b.png")
    assert a.read_bytes() == b.read_bytes()
    with Image.open(a) as im:
        info = dict(im.info)
    assert "Software" not in info and not any("sample" in k.lower() for k in info)


def test_unknown_figure_names_the_known_ones(tmp_path):
    with pytest.raises(ValueError, match="fig3, fig4"):
        plotting.draw("fig7", {}, {})
