"""Replicate studies (issue 12): seeds, sweeps, coverage arithmetic, design, and a fast coverage check."""

from __future__ import annotations

import copy
import csv
import io
import math

import numpy as np
import pytest
import xarray as xr
import yaml
from helpers import fake_replicates
from scipy import stats

from ballbat.config_checks import validate_config
from ballbat.pipeline.config import ConfigError
from ballbat.pipeline.ncio import read_table_csv
from ballbat.studies import batch as study_batch
from ballbat.studies import replicates
from ballbat.studies.coverage import COVERAGE_COLUMNS, combine, coverage, coverage_csv
from ballbat.studies.design import impacts_required
from ballbat.studies.replicates import STUDY_QUANTITIES, TooManyRefused, replicate_seeds, replicate_source
from ballbat.studies.settings import StudySettings
from ballbat.studies.sweeps import point_dataset
from ballbat.studies.truth import population_truth


def settings(config, name="calibration", **over):
    cfg = copy.deepcopy(config)
    cfg["studies"][name].update(over)
    return StudySettings.from_config(cfg, name)


def test_seeds_are_reproducible_and_independent():
    a = [replicate_seeds(7, k) for k in range(200)]
    assert a == [replicate_seeds(7, k) for k in range(200)]
    flat = [s for pair in a for s in pair]
    assert len(set(flat)) == len(flat)  # every experiment and every rendering has its own stream
    assert replicate_seeds(8, 0) != a[0]


def test_batches_cover_every_replicate_once(config):
    s = settings(config, "design", replicates=7, batch_size=3)
    seen = [g for b in range(s.n_batches) for g in s.batch_range(b)]
    assert seen == list(range(7 * len(s.values)))
    with pytest.raises(ValueError, match="out of range"):
        s.batch_range(s.n_batches)


@pytest.mark.parametrize(
    ("parameter", "value", "check"),
    [
        ("impacts_per_bat", 9, lambda d: {n for v in d["synthetic"]["impacts"].values() for n in v.values()} == {9}),
        ("e_x", 0.3, lambda d: {e for v in d["synthetic"]["e_x"].values() for e in v.values()} == {0.3}),
        ("pixel_noise_px", 3.5, lambda d: {c["pixel_noise_px"] for c in d["render"]["cameras"].values()} == {3.5}),
        ("spin_fps", 2000, lambda d: d["render"]["cameras"]["spin"]["fps"] == 2000),
        ("noise_scale", 2.0, lambda d: d["synthetic"]["noise"]["omega_rpm"] == 150.0),
    ],
)
def test_sweep_sets_the_dataset(config, parameter, value, check):
    base = config["datasets"]["synthetic"]
    before = copy.deepcopy(base)
    assert check(point_dataset(base, parameter, value))
    assert base == before  # a copy: the config is untouched


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda c: c["studies"]["calibration"].update(dataset="nope"),
            "studies.calibration.dataset: no dataset 'nope'",
        ),
        (
            lambda c: c["studies"]["design"]["sweep"].update(values=[5, 2.5]),
            "studies.design.sweep.values[1]: impacts per bat must be a whole number >= 3",
        ),
        (
            lambda c: c["studies"]["design"]["sweep"].update(parameter="noise_scale"),
            "studies.design.sweep.parameter: noise_scale scales the direct noise, but the dataset renders tracks",
        ),
        (lambda c: c["studies"]["calibration"].update(replicates=1), "studies.calibration.replicates"),
        (
            lambda c: c["studies"]["calibration"].update(truth_impacts=10**7),
            "studies.calibration.truth_impacts: 70,000,092 impacts need about",  # 108 x ceil(7e7 / 108)
        ),
        (lambda c: c["studies"]["calibration"].update(colour=1), "studies.calibration"),
    ],
)
def test_hostile_study_configs_are_named(raw, schema, edit, message):
    edit(raw)
    with pytest.raises(ConfigError) as err:
        validate_config(raw, schema, available=24 * 2**30)
    assert message in str(err.value)


def test_dropping_a_dataset_drops_its_studies(raw, schema):
    from ballbat.pipeline.config import drop_nulls

    raw["datasets"] = {"synthetic": None, "lab": {"impacts": "x.csv"}}
    cfg = validate_config(drop_nulls(raw), schema, available=24 * 2**30)
    assert cfg["studies"] == {}
    raw2 = yaml.safe_load(yaml.safe_dump(raw))
    raw2["datasets"] = {"synthetic": {"synthetic": {}}, "lab": {"impacts": "x.csv"}}
    raw2["studies"] = {"calibration": None, "design": {"dataset": "synthetic", "replicates": 3, "seed": 1}}
    assert list(drop_nulls(raw2)["studies"]) == ["design"]


def test_drawing_properties_from_tables_without_uncertainties_is_refused_before_the_dag(raw, schema):
    """draw_properties with tables that state no *_err: one line at the config check, not a failed job."""
    raw["studies"]["calibration"]["draw_properties"] = True
    with pytest.raises(ConfigError, match=r"studies.calibration.draw_properties: the tables .* state no uncertainty"):
        validate_config(raw, schema, available=24 * 2**30)
    raw["datasets"]["synthetic"]["bats"] = "config/examples/property_study_bats.csv"
    raw["datasets"]["synthetic"]["synthetic"]["impacts"] = {"baseball": {"hickory": 10}}
    raw["datasets"]["synthetic"]["synthetic"]["e_x"] = {"baseball": {"hickory": 0.455}}
    raw["datasets"]["synthetic"]["synthetic"]["e_y"] = {"baseball": 0.45}
    raw["datasets"]["synthetic"]["synthetic"]["psi_deg"] = {"baseball": [0.0, 30.0]}
    raw["studies"] = {"calibration": raw["studies"]["calibration"]}
    raw["implications"]["scenarios"] = {}
    assert validate_config(raw, schema, available=24 * 2**30)["studies"]["calibration"]["draw_properties"]


def test_a_study_of_a_measured_dataset_is_refused(raw, schema):
    raw["datasets"]["lab"] = {"impacts": "x.csv"}
    raw["studies"]["calibration"]["dataset"] = "lab"
    with pytest.raises(ConfigError, match="'lab' is not synthetic"):
        validate_config(raw, schema, available=24 * 2**30)


def test_a_frame_rate_sweep_needs_rendered_tracks(raw, schema):
    raw["datasets"]["synthetic"]["render"]["enabled"] = False
    raw["studies"]["design"]["sweep"] = {"parameter": "spin_fps", "values": [1000]}
    with pytest.raises(ConfigError, match="spin_fps needs a dataset that renders camera tracks"):
        validate_config(raw, schema, available=24 * 2**30)


def test_coverage_arithmetic():
    """Honest errors cover 68 % / 95 %; errors half the truth's spread cover far less, as the normal law says."""
    good = coverage(fake_replicates(20000, 0.01, 0.01)).isel(point=0, quantity=0)
    assert good.coverage_95 == pytest.approx(0.95, abs=4 * float(good.coverage_95_err))
    assert good.coverage_68 == pytest.approx(0.6827, abs=4 * float(good.coverage_68_err))
    assert good.spread_over_se == pytest.approx(1.0, abs=0.03)
    assert abs(float(good.bias_over_se)) < 4 * float(good.bias_over_se_err)
    bad = coverage(fake_replicates(20000, 0.005, 0.01)).isel(point=0, quantity=0)
    assert bad.coverage_95 == pytest.approx(2 * stats.norm.cdf(0.98) - 1, abs=0.01)
    assert bad.spread_over_se == pytest.approx(2.0, abs=0.05)
    # Student's t: with 5 degrees of freedom the 95 % interval is 2.571 SE wide on each side
    t = fake_replicates(20000, 0.01, 0.01 * math.sqrt(5 / 3), dof=5, seed=1)
    t["value"][:] = 1.0 + 0.01 * np.random.default_rng(2).standard_t(5, (20000, 1))
    cov_t = coverage(t).isel(point=0, quantity=0)
    assert cov_t.coverage_95 == pytest.approx(0.95, abs=0.01)


def test_the_truths_own_sampling_error_goes_into_the_bias_error():
    """A design's truth comes from a finite experiment: its scatter, the replicates' own truths' over sqrt(scale).

    Own noise-free estimates scatter by 0.01 about the population value; the truth's experiment
    repeats the design 100 times, so the truth is known to 0.001, a tenth of the reported 0.01.
    The bias's error is the replicates' 0.01 / sqrt(400) = 0.05 SE and that 0.1 in quadrature.
    A conditional truth (each replicate's own) has none.
    """
    n = 400
    a = fake_replicates(n, 0.01, 0.01, seed=3)
    b = fake_replicates(n, 0.01, 0.01, seed=4)
    b = b.assign_coords(quantity=["mu_k_lower_bound:baseball:"], quantity_name=("quantity", ["mu_k_lower_bound"]))
    rep = xr.concat([a, b], dim="quantity", data_vars="minimal", coords="minimal", compat="override")
    rng = np.random.default_rng(5)
    own = 1.0 + 0.01 * rng.standard_normal((n, 2))
    rep["truth"][:] = own
    rep["value"][:] = own + 0.01 * rng.standard_normal((n, 2))
    truths = [{"e_x:baseball:wood": 1.0, "mu_k_lower_bound:baseball:": 1.0}]
    cov = coverage(rep, truths, [100.0]).isel(point=0)
    plain = coverage(rep, truths).isel(point=0)
    te = cov.truth_error_over_se.values
    assert te[0] == pytest.approx(0.1, rel=0.1)
    assert np.isnan(te[1]) and np.isnan(plain.truth_error_over_se.values).all()
    stat = plain.bias_over_se_err.values
    assert cov.bias_over_se_err.values[0] == pytest.approx(math.hypot(stat[0], te[0]), rel=1e-12)
    assert cov.bias_over_se_err.values[1] == stat[1]
    assert cov.bias_over_se.values == pytest.approx(plain.bias_over_se.values)
    text = coverage_csv(coverage(rep, truths, [100.0]))
    assert "truth_error_over_se" in text.splitlines()[0].split(",")


def test_impacts_required_matches_the_normal_formula_for_many_impacts():
    # sigma with n_at impacts -> single-impact sigma s1; large n: n = 2 (z_a + z_b)^2 s1^2 / delta^2
    s1, delta = 0.1, 0.02
    n_normal = 2 * (stats.norm.ppf(0.975) + stats.norm.ppf(0.8)) ** 2 * s1**2 / delta**2
    n = impacts_required(s1 / math.sqrt(20), 20, delta)
    assert n_normal < n < n_normal * 1.03  # t quantiles: a little more than the normal answer
    assert impacts_required(s1 / math.sqrt(20), 20, 2 * delta) < n
    assert impacts_required(1e-6, 20, delta) == 3
    assert math.isnan(impacts_required(math.nan, 20, delta))
    assert impacts_required(1.0, 20, 1e-6) == math.inf


@pytest.mark.slow  # seconds (quiet machine): more than a unit test may take
def test_replicates_cover_the_truth(config, balls, bats):
    """A fast coverage check of the whole chain: 40 replicates of the default experiment (raw tracks).

    e_x of every bat and ball: 280 intervals cover their truth about 95 % of the time and the
    estimates scatter as their standard errors say. (The 1000-replicate calibration study,
    `make study`, is the full check; its figures are in docs/studies.md and the issue notes.)
    """
    s = settings(config, replicates=40, batch_size=40, truth_impacts=400)
    batch = study_batch.run(s, 0, balls, bats)
    assert batch.sizes == {"replicate": 40, "quantity": 21}
    truths = [population_truth(s, 0, balls, bats)]
    cov = coverage(combine([batch]), truths).isel(point=0)
    ex = cov.where(cov.quantity_name == "e_x", drop=True)
    n = int(ex.n_replicates.sum())
    assert n == 280
    c95 = float((ex.coverage_95 * ex.n_replicates).sum()) / n
    assert 0.90 <= c95 <= 0.99, c95
    ratio = float(ex.spread_over_se.mean())
    assert 0.85 <= ratio <= 1.15, ratio
    # every recorded quantity has its truth and an honest label of its uncertainty
    assert set(cov.quantity_name.values) == set(STUDY_QUANTITIES)
    assert np.all(cov.n_replicates.values == 40)
    assert all(cov.error_kind.values)
    # eta^2's interval uses the Bell-McCaffrey degrees of freedom of its bat-stratified sandwich
    eta = batch.dof.isel(quantity=np.flatnonzero(batch.quantity_name.values == "eta2")).values
    assert eta.size == 80 and np.all((eta > 5) & (eta < 60)) and not np.all(eta == np.round(eta))
    assert "centred within bats" in str(cov.error_kind.values[list(cov.quantity_name.values).index("eta2")])
    # implied e_y's interval has n - k degrees of freedom, k = the ball's bats + 1 (its variance's n / (n - k)):
    # the Eq. ratio slope's n - 1 less the ball's bats (3 baseball, 4 softball)
    for ball, n_bats in (("baseball", 3), ("softball", 4)):
        dof_ey = batch.dof.sel(quantity=f"e_y_implied:{ball}:").values
        dof_ratio = batch.dof.sel(quantity=f"tan_ratio_slope:{ball}:").values
        np.testing.assert_array_equal(dof_ratio - dof_ey, n_bats)


@pytest.mark.slow
def test_study_rules_through_snakemake(lab_run, tmp_path):
    """`snakemake studies` (the lab run's, conftest.LAB_STUDIES, of dataset small): batches, coverage and
    design files with units and provenance; `all` runs none; the report holds every study's figures.
    """
    from workflow_helpers import assert_cf, assert_not_blank, copy_run, make_workdir, planned_jobs, snakemake

    assert not any(r.startswith("study") for r in planned_jobs(make_workdir(tmp_path)))  # a default run makes no study
    res = lab_run / "results" / "studies"
    assert sorted(p.name for p in (res / "calibration" / "batches").iterdir()) == ["batch0.nc", "batch1.nc"]
    cov = xr.open_dataset(res / "calibration" / "coverage.nc")
    n_q = 3 + 2 * 7  # small: e_x of 3 bats; per ball, pooled e_x, 3 slopes, e_y, the mu_k bound, eta^2
    assert cov.sizes == {"point": 1, "quantity": n_q}
    assert all("units" in cov[v].attrs or cov[v].attrs.get("units_from") == "units" for v in cov.data_vars)
    assert cov.attrs["provenance_rule"] == "study_aggregate"
    truth = xr.open_dataset(res / "calibration" / "truth.nc")
    assert truth.attrs["provenance_rule"] == "study_truth" and truth.attrs["truth_impacts"] == 40
    assert set(truth.quantity.values) == set(cov.quantity.values)
    judged = cov.quantity.values[cov.quantity_name.values != "mu_k_lower_bound"]  # the others: the design's truth
    assert np.allclose(
        truth.truth.sel(quantity=judged).values, cov.mean_truth.sel(quantity=judged).values, rtol=1e-12, equal_nan=True
    )
    assert int(cov.n_replicates.max()) == 4
    rows = list(csv.DictReader(io.StringIO(read_table_csv(res / "calibration" / "coverage.csv"))))
    assert len(rows) == n_q and set(rows[0]) == set(COVERAGE_COLUMNS)
    design = list(csv.DictReader(io.StringIO(read_table_csv(res / "design" / "design.csv"))))
    per_size = len(design) // 2
    assert per_size >= 3 and [r["setting"] for r in design] == ["5"] * per_size + ["8"] * per_size
    assert all(float(r["impacts_required"]) >= 3 for r in design)
    for png in ("calibration/coverage.png", "design/coverage.png", "design/design.png"):
        assert_not_blank(res / png)
    one_per_rule = ["calibration/truth/point0.nc", "calibration/truth.nc", "calibration/batches/batch0.nc"]
    one_per_rule += ["calibration/coverage.nc", "design/design.nc", "robustness/coverage.nc"]  # a grid's columns
    assert_cf([str(res / f) for f in one_per_rule], tmp_path / "cf.json")
    # the report's front page: one line per study (rule report_front_studies), shown when the report holds them
    front = (res / "front.rst").read_text()
    assert f"**calibration** (4 replicates per point, {n_q} quantities): 95 % intervals cover the truth in" in front
    assert "**design** (2 replicates per point" in front and "impacts per bat to tell two bats" in front
    wd = copy_run(lab_run, tmp_path / "wd")
    snakemake(wd, "--report", "results/report.html", "studies", "studies_on_request")
    html = (wd / "results" / "report.html").read_text()
    assert "Replicate studies" in html and "What was run" not in html  # no dataset's target: no run's front page
    assert "grid.png" in html and "Grid study" in html


@pytest.mark.slow  # about 3 s: 8 replicates in two batchings
def test_replicates_do_not_depend_on_the_batch_size(config, balls, bats):
    """Replicate k is the same experiment whether it runs in batch 0 of 4 or batch 1 of 3."""
    three = settings(config, replicates=4, batch_size=3, truth_impacts=60)
    b = xr.concat([study_batch.run(three, i, balls, bats) for i in (0, 1)], "replicate")
    one = study_batch.run(settings(config, replicates=4, batch_size=4, truth_impacts=60), 0, balls, bats)
    np.testing.assert_array_equal(one.value.values, b.value.values)


# ---------------------------------------------------------------------------------------
# a replicate runs the workflow's own stages (issue 20): every render and reduce setting


def _small_dataset(config):
    ds = copy.deepcopy(config["datasets"]["synthetic"])
    ds["synthetic"]["impacts"] = {"baseball": {"wood": 6, "metal_rough": 6}, "softball": {"wood": 6}}
    e_x = ds["synthetic"]["e_x"]
    ds["synthetic"]["e_x"] = {
        ball: {bat: e_x[ball][bat] for bat in bats} for ball, bats in ds["synthetic"]["impacts"].items()
    }
    return ds


RENDER_EDITS = {
    "min_frames": lambda r: r.update(min_frames={"tip": 5, "flight": 20, "spin": 4}),
    "swing fps": lambda r: r["cameras"]["swing"].update(fps=4000.0),
    "spin fps": lambda r: r["cameras"]["spin"].update(fps=1500.0),
    "m_per_px": lambda r: r["cameras"]["swing"].update(m_per_px=0.0008),
    "m_per_px_err": lambda r: r["cameras"]["swing"].update(m_per_px_err=0.02),
    "mirror": lambda r: r["cameras"]["spin"].update(mirror=True),
    "pixel noise": lambda r: r["cameras"]["swing"].update(pixel_noise_px=3.5),
    "tee": lambda r: r["cameras"]["spin"].update(tee_px=[500.0, 420.0]),
    "pre-impact frames": lambda r: r["cameras"]["swing"].update(pre_impact_frames=8),
    "max frames": lambda r: r["cameras"]["spin"].update(max_frames=40),
    "rig": lambda r: r.update(rig={"pivot_to_tip_in": 33.0, "pivot_to_impact_in": 26.0}),
    "contact": lambda r: r.update(contact_ms=[0.8, 1.0]),
    "slowdown": lambda r: r.update(bat_slowdown=[0.2, 0.3]),
    "tilted": lambda r: r.update(tilted_fraction=0.3),
    "swing plane": lambda r: r.update(swing_plane_deg=[0.0, 20.0]),
}


@pytest.mark.parametrize("edit", list(RENDER_EDITS))
def test_a_replicate_and_the_workflow_reduce_alike(config, balls, bats, root, tmp_path, edit):
    """The study's in-memory replicate and the workflow's render_tracks -> tracks.nc -> reduce give
    the same reduced impacts, whichever render or reduce setting is changed (min_frames was once
    honoured by the workflow alone).
    """
    from ballbat import systematics
    from ballbat.stages import reduce, render, simulate
    from ballbat.synthetic import SyntheticSettings
    from ballbat.tracks.data import camera_block
    from ballbat.tracks.io import load_tracks
    from ballbat.tracks.render import settings_from_config

    raw = copy.deepcopy(config)
    ds = _small_dataset(raw)
    RENDER_EDITS[edit](ds["render"])
    raw["datasets"] = {"synthetic": ds}
    raw.pop("studies", None)
    schema = yaml.safe_load((root / "workflow" / "schemas" / "config.schema.yaml").read_text())
    ds = validate_config(raw, schema)["datasets"]["synthetic"]
    seeds = (11, 12)
    replicate = replicate_source(ds, seeds, balls, bats)
    sim = simulate.run(SyntheticSettings(**{**ds["synthetic"], "seed": seeds[0]}), balls, bats)
    cfg = {**ds["render"], "seed": seeds[1]}
    tracks_nc = tmp_path / "tracks.nc"
    render.run(settings_from_config(cfg), sim, balls).to_netcdf(tracks_nc)
    settings = reduce.ReduceSettings.from_config(camera_block(cfg), "render", systematics=True)
    workflow = reduce.run(settings, load_tracks(tracks_nc, None, balls, bats), balls, bats)
    # the workflow's reduce also reduces again at +-1 sigma of each calibration (ballbat.systematics);
    # a replicate judges no systematic
    calibration = {n for n in workflow.data_vars if "systematic" in workflow[n].dims}
    assert calibration == {"systematic_rel_sigma", *(f"{k}_shift" for k in systematics.SHIFTED)}
    assert set(replicate.data_vars) == set(workflow.data_vars) - calibration
    for name in replicate.data_vars:
        a, b = replicate[name].values, workflow[name].values
        if a.dtype.kind == "f":
            # the workflow's tracks make a round trip through tracks.nc, which keeps fewer empty
            # columns: the sums' rounding differs in the last bit, and the contact prior's
            # Nelder-Mead optimum (tolerance 1e-3 in its parameters) can carry it to about 1e-8
            # (relative) in the contact time and 1e-11 in v_bat; a setting honoured differently
            # moves them by far more
            np.testing.assert_allclose(a, b, rtol=1e-7, atol=0, err_msg=f"{edit}: {name}")
        else:
            np.testing.assert_array_equal(a, b, err_msg=f"{edit}: {name}")
    usable = int((workflow["ingest_flag"].values == 0).sum())
    assert 0 < usable <= workflow.sizes["impact"]
    if edit == "min_frames":  # the setting bites: impacts with 5-19 flight frames are excluded
        assert usable < workflow.sizes["impact"]


def test_combined_interval_takes_welch_satterthwaite_degrees_of_freedom():
    """A combined interval t x sqrt(u^2 + s^2) with a stated (exact) systematic s needs nu_eff, not u's nu.

    With the statistical t quantile of 10 degrees of freedom and a systematic 3x the statistical
    error, the interval is 13 % too wide and covers about 97.5 %; the robustness grid showed it as
    99-100 % at 12-30 impacts per bat (docs/studies.md). With nu_eff = nu (u^2 + s^2)^2 / u^4
    (GUM G.4) it covers 95 %.
    """
    from ballbat.studies.coverage import _t
    from ballbat.studies.records import combined_dof

    assert combined_dof(1.0, 0.0, 10.0) == 10.0
    assert combined_dof(1.0, 1.0, 10.0) == 40.0
    assert combined_dof(0.0, 1.0, 10.0) == np.inf
    rng = np.random.default_rng(2)
    n, nu, s = 40000, 10.0, 3.0
    u = np.sqrt(rng.chisquare(nu, n) / nu)  # the stated statistical error, true value 1
    d = rng.standard_normal(n) + s * rng.standard_normal(n)
    total = np.hypot(u, s)
    ws = np.mean(np.abs(d) <= _t(0.95, combined_dof(u, s, nu)) * total)
    held = np.mean(np.abs(d) <= _t(0.95, np.full(n, nu)) * total)
    assert abs(ws - 0.95) < 0.005, ws
    assert held > 0.97, held


def _fake_rows(value: float) -> list[dict]:
    row = {"quantity": "e_x", "ball": "baseball", "bat": "wood", "value": value, "uncertainty": 0.01, "truth": 0.35}
    return [{**row, "dof": math.inf, "units": "1", "systematic": math.nan, "calibration_effect": math.nan}]


def test_a_refused_replicate_is_counted_and_the_batch_goes_on(config, balls, bats, monkeypatch):
    """A check's false alarm on one replicate (its data refused) must not stop a study of thousands: the
    batch records why (``refusal``), gives it no estimates, and the coverage table counts it (``n_refused``)
    apart from the replicates it judges.
    """
    from ballbat.properties import InputError

    def fake(settings, dataset, replicate, balls, bats, check=True):
        if replicate == 3:
            raise InputError(["render (replicate 3).cameras.spin: g is negative: y points up"])
        return _fake_rows(0.35 + 0.01 * (replicate - 5) / 5)

    monkeypatch.setattr(replicates, "run_replicate", fake)
    s = settings(config, replicates=20, batch_size=20)
    batch = study_batch.run(s, 0, balls, bats)
    why = batch["refusal"].values.astype(str)
    assert [i for i, w in enumerate(why) if w] == [3]
    assert "replicate 3" in why[3] and "y points up" in why[3]
    assert np.isnan(batch["value"].values[3]).all() and np.isfinite(batch["value"].values[:3]).all()
    cov = coverage(combine([batch]))
    assert int(cov["n_refused"].values[0, 0]) == 1 and int(cov["n_replicates"].values[0, 0]) == 19
    header = coverage_csv(cov).splitlines()[0].split(",")
    assert header[header.index("n_replicates") + 1] == "n_refused"


def test_a_batch_whose_data_are_refused_again_and_again_stops_with_the_first_reason(config, balls, bats, monkeypatch):
    """More refusals than false alarms explain (over 5 % of a batch) are a wrong setting: the batch stops
    at once with the first reason, instead of running on to a study of nothing.
    """
    from ballbat.properties import InputError

    calls = []

    def fake(settings, dataset, replicate, balls, bats, check=True):
        calls.append(replicate)
        raise InputError([f"tracks.cameras.swing: fps wrong (replicate {replicate})"])

    monkeypatch.setattr(replicates, "run_replicate", fake)
    s = settings(config, replicates=40, batch_size=40)
    with pytest.raises(TooManyRefused, match=r"refused 3 of its first 3 replicates.*replicate 0\)"):
        study_batch.run(s, 0, balls, bats)
    assert len(calls) == 3  # 5 % of 40: two may be false alarms, the third stops it
