"""Studies that test systematics (issue 22): grid sweeps, contact-time sweep, drawn calibration, combined intervals."""

from __future__ import annotations

import copy
import csv
import io
import itertools

import numpy as np
import pytest
import xarray as xr

from ballbat.config_checks import validate_config
from ballbat.pipeline.config import ConfigError
from ballbat.studies import batch as study_batch
from ballbat.studies.coverage import EmptySweepPoint, coverage, coverage_csv
from ballbat.studies.records import row_labels
from ballbat.studies.replicates import replicate_seeds, run_replicate
from ballbat.studies.settings import StudySettings
from ballbat.studies.sweeps import CONTACT_HALF_WIDTH_MS, point_dataset, sweep_points
from ballbat.studies.truth import merge_truths, truth_dataset, truth_scales_from_dataset, truths_from_dataset
from ballbat.tracks.data import camera_block
from ballbat.tracks.render import calibration_draws, drawn_calibration, settings_from_config

# ---------------------------------------------------------------------------------------
# the grid


def test_the_shipped_robustness_grid_expands_to_the_product(config):
    """27 points, the first setting slowest; each point's dataset has its noise, impacts and contact range."""
    s = StudySettings.from_config(config, "robustness")
    grid = config["studies"]["robustness"]["sweep"]["grid"]
    assert s.parameters == ("pixel_noise_px", "impacts_per_bat", "contact_ms") and s.is_grid
    assert s.values == tuple(itertools.product(*grid.values()))
    assert s.n_points == 27 and s.total == 27 * s.replicates
    assert s.point_settings().shape == (27, 3)
    for px, n, tc in s.values:
        ds = point_dataset(s.dataset, s.parameter, (px, n, tc))
        assert {c["pixel_noise_px"] for c in ds["render"]["cameras"].values()} == {px}
        assert {k for per in ds["synthetic"]["impacts"].values() for k in per.values()} == {int(n)}
        assert ds["render"]["contact_ms"] == pytest.approx([tc - 0.05, tc + 0.05])
        assert ds["render"]["draw_calibration"] is True  # the study draws its calibration
    # every replicate number maps to one point and replicate, each once
    seen = [divmod(g, s.replicates) for b in range(s.n_batches) for g in s.batch_range(b)]
    assert len(set(seen)) == s.total and max(p for p, _ in seen) == 26
    # one-parameter sweeps are as they were (the shipped design study)
    d = StudySettings.from_config(config, "design")
    assert d.parameter == "impacts_per_bat" and d.values == (5.0, 10.0, 20.0, 30.0, 50.0, 75.0, 100.0)
    assert not d.is_grid and d.point_settings()[:, 0].tolist() == list(d.values)
    assert StudySettings.from_config(config, "calibration").parameters == ()


def test_sweep_points_of_one_parameter_and_of_a_grid():
    assert sweep_points(None) == ((), [])
    assert sweep_points({"parameter": "e_x", "values": [0.3, 0.5]}) == (("e_x",), [(0.3,), (0.5,)])
    names, pts = sweep_points({"grid": {"e_x": [0.3, 0.5], "impacts_per_bat": [10, 20, 30]}})
    assert names == ("e_x", "impacts_per_bat") and len(pts) == 6 and pts[:3] == [(0.3, 10), (0.3, 20), (0.3, 30)]


def test_contact_sweep_sets_a_narrow_range_about_the_value(config):
    base = config["datasets"]["synthetic"]
    ds = point_dataset(base, "contact_ms", 0.8)
    assert ds["render"]["contact_ms"] == pytest.approx([0.8 - CONTACT_HALF_WIDTH_MS, 0.8 + CONTACT_HALF_WIDTH_MS])
    assert base["render"].get("contact_ms") != ds["render"]["contact_ms"]  # a copy
    assert settings_from_config(ds["render"]).contact_time == pytest.approx((0.75e-3, 0.85e-3))


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda g: g.update(contact_ms=[0.5, 0.1]),
            "studies.robustness.sweep.grid.contact_ms[1]: contact_ms must lie in [0.25, 1.95] ms",
        ),
        (
            lambda g: g.update(contact_ms=[1.98]),
            "studies.robustness.sweep.grid.contact_ms[0]: contact_ms must lie in [0.25, 1.95] ms",
        ),
        (
            lambda g: g.update(impacts_per_bat=[12, 2.5]),
            "studies.robustness.sweep.grid.impacts_per_bat[1]: impacts per bat must be a whole number >= 3",
        ),
        (
            lambda g: g.update(pixel_noise_px=[0.0, 3.0]),
            "studies.robustness.sweep.grid.pixel_noise_px[0]: pixel_noise_px must be positive in a study",
        ),
        (  # the schema owns the range of a swept setting (0 to 100 px), as of any other
            lambda g: g.update(pixel_noise_px=[2.0, 150.0]),
            "studies.robustness.sweep (pixel_noise_px = 150): render.cameras.swing.pixel_noise_px: 150.0 is greater "
            "than the maximum of 100",
        ),
        (lambda g: g.update(pixel_noise_px=[1.0, 1.0]), "studies.robustness.sweep.grid.pixel_noise_px: a value is"),
        (
            lambda g: g.update(noise_scale=[2.0]),
            "studies.robustness.sweep.grid.noise_scale: noise_scale scales the direct noise",
        ),
        (lambda g: g.update(colour=[1.0]), "studies.robustness.sweep"),
        (lambda g: g.update(contact_ms=[]), "studies.robustness.sweep"),
    ],
)
def test_invalid_grid_values_are_named(raw, schema, edit, message):
    edit(raw["studies"]["robustness"]["sweep"]["grid"])
    with pytest.raises(ConfigError) as err:
        validate_config(raw, schema, available=24 * 2**30)
    assert message in str(err.value)


def test_grid_and_one_parameter_sweep_are_exclusive(raw, schema):
    raw["studies"]["robustness"]["sweep"].update(parameter="e_x", values=[0.3])
    with pytest.raises(ConfigError, match=r"studies\.robustness\.sweep"):
        validate_config(raw, schema, available=24 * 2**30)


def test_a_contact_sweep_or_drawn_calibration_needs_rendered_tracks(raw, schema):
    raw["datasets"]["synthetic"]["render"]["enabled"] = False
    raw["studies"]["robustness"]["sweep"]["grid"] = {"contact_ms": [0.6], "impacts_per_bat": [12]}
    with pytest.raises(ConfigError) as err:
        validate_config(raw, schema, available=24 * 2**30)
    assert "studies.robustness.sweep.grid.contact_ms: contact_ms needs a dataset that renders camera tracks" in str(
        err.value
    )
    assert "studies.robustness.draw_calibration: needs a dataset that renders camera tracks" in str(err.value)


def test_drawing_a_calibration_without_an_uncertainty_is_refused(raw, schema):
    raw["datasets"]["synthetic"]["render"]["cameras"]["swing"]["m_per_px_err"] = 0.0
    with pytest.raises(ConfigError, match=r"studies\.robustness\.draw_calibration: the dataset states no calibration"):
        validate_config(raw, schema, available=24 * 2**30)


def test_the_robustness_study_is_on_request(config):
    assert config["studies"]["robustness"]["on_request"] is True
    assert not config["studies"]["calibration"]["on_request"]  # the schema's default


# ---------------------------------------------------------------------------------------
# drawn calibration


def _render_cfg(config, seed=5, **swing):
    cfg = copy.deepcopy(config["datasets"]["synthetic"]["render"])
    cfg["cameras"]["swing"].update(swing)
    return {**cfg, "seed": seed}


def test_drawn_calibration_changes_the_renderer_scale_not_the_reduction(config):
    cfg = _render_cfg(config)
    declared = settings_from_config(cfg)
    assert declared.swing.camera.m_per_px == cfg["cameras"]["swing"]["m_per_px"]  # off by default
    drawn = settings_from_config({**cfg, "draw_calibration": True})
    rel = drawn.swing.camera.m_per_px / declared.swing.camera.m_per_px - 1
    assert rel != 0 and abs(rel) < 5 * cfg["cameras"]["swing"]["m_per_px_err"]
    assert drawn.spin.camera.m_per_px == declared.spin.camera.m_per_px  # no uncertainty stated: not drawn
    assert drawn.swing.camera.fps == declared.swing.camera.fps and drawn.rig == declared.rig
    # the reduction reads the declared block
    block = camera_block({**cfg, "draw_calibration": True})
    assert block["cameras"]["swing"]["m_per_px"] == cfg["cameras"]["swing"]["m_per_px"]
    # reproducible from the render seed, another seed another draw
    again = settings_from_config({**cfg, "draw_calibration": True})
    assert again.swing.camera.m_per_px == drawn.swing.camera.m_per_px
    other = settings_from_config({**_render_cfg(config, seed=6), "draw_calibration": True})
    assert other.swing.camera.m_per_px != drawn.swing.camera.m_per_px


def test_drawn_scales_spread_as_stated():
    cfg = {
        "cameras": {  # every uncertainty given, as in the validated config (0: none stated)
            "swing": {"m_per_px": 1e-3, "m_per_px_err": 0.01, "fps_err": 0.0},
            "spin": {"m_per_px": 2e-3, "m_per_px_err": 0.0, "fps_err": 0.02},
        },
        "rig": {
            "pivot_to_tip_in": 34.0,
            "pivot_to_impact_in": 28.0,
            "pivot_to_tip_err_in": 0.0,
            "pivot_to_impact_err_in": 0.1,
        },
    }
    cfg["cameras"]["spin"]["fps"] = 1000.0
    cfg["cameras"]["swing"]["fps"] = 3000.0
    draws = [drawn_calibration({**cfg, "seed": k}) for k in range(2000)]
    rel = np.array([d["cameras"]["swing"]["m_per_px"] for d in draws]) / 1e-3 - 1
    assert abs(rel.mean()) < 4 * 0.01 / np.sqrt(2000) and rel.std() == pytest.approx(0.01, rel=0.1)
    fps = np.array([d["cameras"]["spin"]["fps"] for d in draws]) / 1000.0 - 1
    assert fps.std() == pytest.approx(0.02, rel=0.1)  # a stated frame-rate uncertainty is drawn (relative)
    rig = np.array([d["rig"]["pivot_to_impact_in"] for d in draws]) - 28.0
    assert rig.std() == pytest.approx(0.1, rel=0.1)  # a rig length's (absolute, inches)
    assert {d["cameras"]["swing"]["fps"] for d in draws} == {3000.0}  # nothing stated: not drawn
    assert {d["rig"]["pivot_to_tip_in"] for d in draws} == {34.0}
    assert cfg["cameras"]["swing"]["m_per_px"] == 1e-3  # the block itself is untouched


def test_rendered_tracks_scale_with_the_drawn_pixel_scale(config, balls):
    """Noise-free tracks drawn with the drawn scale: every swing-camera displacement from the tee is scaled by
    declared / drawn, while the impacts' own draws (contact time, swing plane...) are the same.
    """
    from ballbat.stages import render, simulate
    from ballbat.synthetic import SyntheticSettings

    syn = copy.deepcopy(config["datasets"]["synthetic"]["synthetic"])
    syn["impacts"] = {"baseball": {"wood": 4}}
    syn["e_x"] = {"baseball": {"wood": 0.46}}
    syn["e_y"] = {"baseball": 0.45}
    syn["psi_deg"] = {"baseball": [0.0, 30.0]}
    from ballbat.properties import load_bats

    bats = load_bats(__import__("pathlib").Path(__file__).resolve().parents[1] / "config" / "bats.csv")
    sim = simulate.run(SyntheticSettings(**{**syn, "seed": 3}), balls, bats)
    cfg = _render_cfg(config, seed=9)
    for cam in cfg["cameras"].values():
        cam["pixel_noise_px"] = 0.0
    plain = render.render(settings_from_config(cfg), sim, balls)
    drawn = render.render(settings_from_config({**cfg, "draw_calibration": True}), sim, balls)
    for k, v in plain.truth.items():
        np.testing.assert_array_equal(v, drawn.truth[k], err_msg=k)
    m0 = cfg["cameras"]["swing"]["m_per_px"]
    m1 = settings_from_config({**cfg, "draw_calibration": True}).swing.camera.m_per_px
    tee = cfg["cameras"]["swing"]["tee_px"][0]
    a = plain.cameras["swing"].x["ball"] - tee
    b = drawn.cameras["swing"].x["ball"] - tee
    both = np.isfinite(a) & np.isfinite(b) & (np.abs(a) > 1)
    assert both.sum() > 20
    np.testing.assert_allclose(b[both] / a[both], m0 / m1, rtol=1e-9)


# ---------------------------------------------------------------------------------------
# combined intervals


def _with_systematic(n=4000, se=0.01, syst=0.02, seed=0):
    """Replicates of two quantities: one whose estimate is off by a shared calibration error of sd ``syst``
    (reported as its systematic), one without a systematic.
    """
    from helpers import fake_replicates

    rng = np.random.default_rng(seed + 1000)  # not fake_replicates' own stream
    a = fake_replicates(n, se, se, seed=seed)
    a["value"] = a["value"] + syst * rng.standard_normal((n, 1))
    a["systematic"] = (("replicate", "quantity"), np.full((n, 1), syst))
    b = fake_replicates(n, se, se, seed=seed + 1).assign_coords(
        quantity=["e_x_pooled:baseball:"], quantity_name=("quantity", ["e_x_pooled"]), bat=("quantity", [""])
    )
    b["systematic"] = (("replicate", "quantity"), np.full((n, 1), np.nan))
    return xr.concat([a, b], dim="quantity", data_vars="minimal", coords="minimal", compat="override")


def test_the_combined_interval_covers_what_the_statistical_one_misses():
    cov = coverage(_with_systematic()).isel(point=0)
    a, b = cov.isel(quantity=0), cov.isel(quantity=1)
    # statistical only: the interval is sqrt(5) too narrow -> 2 Phi(1.96 / sqrt(5)) - 1 = 62 %
    assert float(a.coverage_95) == pytest.approx(0.62, abs=0.03)
    assert float(a.coverage_95_combined) == pytest.approx(0.95, abs=4 * float(a.coverage_95_combined_err))
    assert float(a.coverage_95_combined) > float(a.coverage_95) + 0.2
    assert float(a.coverage_68_combined) == pytest.approx(0.6827, abs=0.03)
    assert float(a.mean_systematic) == pytest.approx(0.02) and int(a.n_systematic) == 4000
    # no systematic: no combined coverage (not the statistical one again)
    assert np.isnan(float(b.coverage_95_combined)) and int(b.n_systematic) == 0
    assert float(b.coverage_95) == pytest.approx(0.95, abs=0.015)
    text = coverage_csv(coverage(_with_systematic(n=200)))
    rows = list(csv.DictReader(io.StringIO(text.split("# ballbat table:")[0])))
    assert rows[1]["coverage_95_combined"] == "" and rows[0]["coverage_95_combined"] != ""


def test_the_calibration_effect_takes_the_draw_out_of_bias_spread_and_statistical_coverage():
    """Each value is truth + bias + statistical noise + the drawn calibration's shift (4x the SE, as at
    1 px); calibration_effect is minus that shift. Around value + effect the bias is measured to its statistical
    precision (the raw bias is 4x less sharp), the spread is the statistical one and the statistical
    interval covers 95 %; a replicate without an effect (not drawn) leaves the *_calibrated columns NaN.
    """
    from helpers import fake_replicates

    n, se, syst, bias = 4000, 0.01, 0.04, 0.3
    rng = np.random.default_rng(7)
    a = fake_replicates(n, se, se, seed=3)
    shift = syst * rng.standard_normal((n, 1))
    a["value"] = a["value"] + bias * se + shift
    a["systematic"] = (("replicate", "quantity"), np.full((n, 1), syst))
    a["calibration_effect"] = (("replicate", "quantity"), -shift)
    c = coverage(a).isel(point=0, quantity=0)
    assert float(c.bias_over_se_calibrated) == pytest.approx(bias, abs=4 * float(c.bias_over_se_calibrated_err))
    assert float(c.bias_over_se_calibrated_err) == pytest.approx(1 / np.sqrt(n), rel=0.1)
    assert float(c.bias_over_se_err) > 3.5 * float(c.bias_over_se_calibrated_err)  # the draw's spread
    assert float(c.spread_over_se_calibrated) == pytest.approx(1.0, abs=0.04)
    assert float(c.spread_over_se) == pytest.approx(np.hypot(1, 4), rel=0.05)
    # the statistical interval around value + effect, with the bias of 0.3 SE: 2 Phi(1.96 - 0.3) - 1 - ...
    from scipy import stats

    expected = stats.norm.cdf(1.96 - bias) - stats.norm.cdf(-1.96 - bias)
    assert float(c.coverage_95_calibrated) == pytest.approx(expected, abs=4 * float(c.coverage_95_calibrated_err))
    assert float(c.coverage_95) < 0.5  # the raw statistical interval does not cover the draw
    assert int(c.n_calibrated) == n
    plain = coverage(fake_replicates(200, 0.01, 0.01)).isel(point=0, quantity=0)
    assert int(plain.n_calibrated) == 0 and np.isnan(float(plain.bias_over_se_calibrated))
    assert np.isnan(float(plain.coverage_95_calibrated))
    text = coverage_csv(coverage(a))
    header = text.splitlines()[0].split(",")
    assert {"bias_over_se_calibrated", "coverage_95_calibrated", "spread_over_se_calibrated"} <= set(header)


def test_batches_without_a_systematic_still_aggregate():
    from helpers import fake_replicates

    cov = coverage(fake_replicates(200, 0.01, 0.01)).isel(point=0, quantity=0)
    assert np.isnan(float(cov.coverage_95_combined)) and int(cov.n_systematic) == 0


def _grid_replicates(n=150):
    """Fake replicates of one quantity at the 8 corners of a 2 x 2 x 2 grid (coverage ~95 % everywhere)."""
    from helpers import fake_replicates

    table = np.array(list(itertools.product([1.0, 5.0], [12.0, 60.0], [0.5, 1.0])))
    rep = fake_replicates(n * len(table), 0.01, 0.01)
    rep["point"] = ("replicate", np.repeat(np.arange(len(table)), n))
    rep["systematic"] = (("replicate", "quantity"), np.full((n * len(table), 1), 0.001))
    rep.attrs.update(sweep_parameter="pixel_noise_px,impacts_per_bat,contact_ms", sweep_values=table.ravel())
    return rep, table


def test_grid_coverage_table_and_figure(tmp_path):
    from ballbat.plotting import grid_coverage_figure, save_figure
    from workflow_helpers import assert_not_blank

    rep, table = _grid_replicates()
    cov = coverage(rep)
    assert cov.sizes["point"] == 8
    np.testing.assert_array_equal(cov.grid_setting.values, table)
    assert list(cov.parameter.values) == ["pixel_noise_px", "impacts_per_bat", "contact_ms"]
    assert np.all(np.isnan(cov.setting.values))
    text = coverage_csv(cov)
    header = text.splitlines()[0].split(",")
    assert header[:4] == ["setting", "quantity", "ball", "bat"]  # the header the damaged-product guards know
    assert header[-3:] == ["pixel_noise_px", "impacts_per_bat", "contact_ms"]
    assert "coverage_95_combined" in header
    last = text.splitlines()[8].split(",")
    assert last[:2] == ["pixel_noise_px=5 impacts_per_bat=60 contact_ms=1", "e_x"] and last[-3:] == ["5", "60", "1"]
    save_figure(grid_coverage_figure(cov), tmp_path / "grid.png")
    assert_not_blank(tmp_path / "grid.png")


def test_an_empty_grid_point_is_named():
    rep, _ = _grid_replicates(120)
    rep["value"][rep.point.values == 5] = np.nan
    with pytest.raises(EmptySweepPoint, match="pixel_noise_px = 5, impacts_per_bat = 12, contact_ms = 1"):
        coverage(rep)


def test_a_grid_replicate_records_a_systematic(config, balls, bats):
    """One replicate of a grid point with drawn calibration: every quantity gets its calibration systematic
    (the tracks reduced again at +-1 sigma of the swing camera's pixel scale, as the workflow's reduce does).
    """
    cfg = copy.deepcopy(config)
    cfg["studies"]["robustness"].update(replicates=1, batch_size=1)
    cfg["studies"]["robustness"]["sweep"] = {"grid": {"pixel_noise_px": [3.0], "contact_ms": [0.9]}}
    s = StudySettings.from_config(cfg, "robustness")
    batch = study_batch.run(s, 0, balls, bats)
    assert batch.attrs["sweep_parameter"] == "pixel_noise_px,contact_ms"
    names = batch.quantity_name.values
    syst = batch.systematic.values[0]
    for q in ("e_x", "e_x_pooled", "tan_ratio_slope", "spin_theta_slope", "e_y_implied", "eta2"):
        assert np.all(np.isfinite(syst[names == q])) and np.all(syst[names == q] > 0), q


@pytest.mark.slow
def test_the_robustness_figure_is_in_the_dag(tmp_path):
    """`snakemake -n studies_on_request` plans the grid figure; `studies` (make study) plans no robustness job."""
    from workflow_helpers import make_workdir, snakemake

    wd = make_workdir(tmp_path)
    out = snakemake(wd, "-n", "studies_on_request").stdout
    assert "rule study_grid:" in out and "results/studies/robustness/grid.png" in out
    assert "results/studies/robustness/batches/batch107.nc" in out  # 27 points x 400 replicates in 100s
    assert "results/studies/robustness/" not in snakemake(wd, "-n", "studies").stdout


def test_truth_files_of_single_points_merge_into_the_study_truth(config, balls, bats):
    """One truth job per sweep point (rule study_truth_point), joined by study_truth: the same as all at once."""
    cfg = copy.deepcopy(config)
    cfg["studies"]["robustness"].update(truth_impacts=30)
    cfg["studies"]["robustness"]["sweep"] = {"grid": {"pixel_noise_px": [2.0], "impacts_per_bat": [6, 9]}}
    s = StudySettings.from_config(cfg, "robustness")
    whole = truth_dataset(s, balls, bats)
    parts = [truth_dataset(s, balls, bats, points=[p]) for p in (1, 0)]
    assert [p.point.values.tolist() for p in parts] == [[1], [0]]
    merged = merge_truths(parts)
    np.testing.assert_array_equal(merged.truth.values, whole.truth.values)
    np.testing.assert_array_equal(merged.grid_setting.values, whole.grid_setting.values)
    assert list(merged.quantity.values) == list(whole.quantity.values)
    assert merged.attrs["truth_impacts"] == 30 and merged.attrs["sweep_parameter"] == "pixel_noise_px,impacts_per_bat"
    assert truths_from_dataset(merged) == truths_from_dataset(whole)
    # the truth's experiment repeats the design ceil(30 / 6) = 5 and ceil(30 / 9) = 4 times
    np.testing.assert_array_equal(truth_scales_from_dataset(merged), [5.0, 4.0])
    with pytest.raises(ValueError, match="no truth_scale variable"):
        truth_scales_from_dataset(merged.drop_vars("truth_scale"))
    with pytest.raises(ValueError, match=r"missing \[0\], repeated \[1\]"):
        merge_truths([parts[0], parts[0]])


@pytest.mark.slow
def test_a_small_robustness_study_runs_through_snakemake(lab_run):
    """The on-request grid study through Snakemake (the lab run's, conftest.LAB_STUDIES: 2 points of dataset
    small): a truth job per point, coverage with the grid's columns and combined intervals, the
    grid figure (in the report: test_studies.test_study_rules_through_snakemake).
    """
    from ballbat.pipeline.ncio import read_table_csv
    from workflow_helpers import assert_not_blank

    res = lab_run / "results" / "studies" / "robustness"
    assert sorted(p.name for p in (res / "truth").iterdir()) == ["point0.nc", "point1.nc"]
    truth = xr.open_dataset(res / "truth.nc")
    assert truth.attrs["provenance_rule"] == "study_truth" and truth.sizes["point"] == 2
    rows = list(csv.DictReader(io.StringIO(read_table_csv(res / "coverage.csv"))))
    assert len(rows) == 2 * truth.sizes["quantity"]
    assert rows[-1]["setting"] == "pixel_noise_px=5 impacts_per_bat=6 contact_ms=1"
    assert (rows[-1]["pixel_noise_px"], rows[-1]["contact_ms"]) == ("5", "1")
    ex = [r for r in rows if r["quantity"] == "e_x"]
    assert len(ex) == 2 * 3 and all(
        float(r["mean_systematic"]) > 0 for r in ex
    )  # drawn calibration: e_x's pixel-scale systematic
    assert_not_blank(res / "grid.png")
    assert not (res / "design.csv").exists()  # a grid has no design table


def test_the_calibration_effect_is_what_the_true_calibration_would_have_given(config, balls, bats):
    """A replicate that draws its calibration reports, per quantity, the first-order change the draw made
    (_calibration_effect). Reducing the same tracks with the drawn (true) calibration instead of
    the declared one must give value + calibration_effect, up to second order: the study uses this to
    take the draw's spread out of a bias and to judge the statistical interval where calibration is drawn.
    """
    from helpers import SMALL

    dataset = copy.deepcopy(config["datasets"]["synthetic"])
    dataset["synthetic"]["impacts"] = SMALL
    cams = dataset["render"]["cameras"]
    cams["swing"].update(m_per_px_err=0.01, fps_err=0.003)
    cams["spin"].update(m_per_px_err=0.01)
    dataset["render"]["draw_calibration"] = True
    settings = StudySettings.from_config(
        {**config, "studies": {"s": {**config["studies"]["calibration"], "dataset": "synthetic"}}}, "s"
    )
    replicate = 1
    drawn = run_replicate(settings, dataset, replicate, balls, bats)
    # the lab that knows its true calibration: the drawn one declared, nothing drawn (same seeds: same tracks)
    seeds = replicate_seeds(settings.seed, replicate)
    z = calibration_draws({**dataset["render"], "seed": seeds[1]})
    assert np.all(np.abs(z[[0, 1, 2]]) > 0.2)  # swing and spin scale, swing frame rate: the draws this test needs
    known = copy.deepcopy(dataset)
    true_block = drawn_calibration({**dataset["render"], "seed": seeds[1]})
    for name, cam in known["render"]["cameras"].items():
        cam.update(m_per_px=true_block["cameras"][name]["m_per_px"], fps=true_block["cameras"][name]["fps"])
    known["render"]["draw_calibration"] = False
    plain = run_replicate(settings, known, replicate, balls, bats)
    exact = {row_labels([r])[0]: r["value"] for r in plain}
    moved, missed = [], []
    for r in drawn:
        label = row_labels([r])[0]
        if not np.isfinite(exact[label] - r["value"]):
            continue
        assert np.isfinite(r["calibration_effect"]), label
        # in SE: how far the draw moved the value, and how far value + effect is from the true calibration's
        moved.append((exact[label] - r["value"]) / r["uncertainty"])
        missed.append((exact[label] - r["value"] - r["calibration_effect"]) / r["uncertainty"])
        assert abs(missed[-1]) < 0.25, (label, moved[-1], missed[-1])
    moved, missed = np.abs(moved), np.abs(missed)
    assert len(moved) == 17 and (moved > 1).sum() >= 5 and moved.max() > 2.5  # the draw moved several by > 1 SE
    assert missed.sum() < 0.15 * moved.sum()
    # not drawn: no effect reported
    assert all(np.isnan(r["calibration_effect"]) for r in plain)
