"""Study replicates (ballbat.studies.replicates): a replicate is the stages in memory; the calibration effect
is what the true calibration would have given (issue 22).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml
from helpers import SMALL
from helpers import study_settings as settings

from ballbat.config_checks import validate_config
from ballbat.stages import fit_ex, normalize, reconstruct, reduce, render, simulate
from ballbat.studies import batch as study_batch
from ballbat.studies import replicates
from ballbat.studies.coverage import combine, coverage, coverage_csv
from ballbat.studies.records import row_labels
from ballbat.studies.replicates import (
    STUDY_QUANTITIES,
    TooManyRefused,
    replicate_seeds,
    replicate_source,
    run_replicate,
)
from ballbat.studies.settings import StudySettings
from ballbat.tracks.render import calibration_draws, drawn_calibration


def test_a_replicate_is_the_stages_in_memory(config, balls, bats, monkeypatch):
    """studies.run_replicate calls simulate, render, reduce, normalize, reconstruct and fit_ex's run, once each
    (fit_ex's as :func:`fit_ex.fit`, its run with the signed systematics kept).
    """
    calls = []
    for mod in (simulate, reduce, normalize, reconstruct, fit_ex):
        entry = "fit" if mod is fit_ex else "run"
        orig = getattr(mod, entry)

        def counted(*args, _orig=orig, _name=mod.__name__, **kw):
            calls.append(_name.rsplit(".", 1)[1])
            return _orig(*args, **kw)

        monkeypatch.setattr(mod, entry, counted)
    orig_render = render.render
    monkeypatch.setattr(render, "render", lambda *a, **k: calls.append("render") or orig_render(*a, **k))
    monkeypatch.setattr(replicates, "STUDY_QUANTITIES", tuple(q for q in STUDY_QUANTITIES if q != "eta2"))
    dataset = copy.deepcopy(config["datasets"]["synthetic"])
    dataset["synthetic"]["impacts"] = SMALL
    settings = StudySettings.from_config(
        {**config, "studies": {"s": {**config["studies"]["calibration"], "dataset": "synthetic"}}}, "s"
    )
    rows = run_replicate(settings, dataset, 0, balls, bats)
    assert calls == ["simulate", "render", "reduce", "normalize", "reconstruct", "fit_ex"]
    e_x = [r for r in rows if r["quantity"] == "e_x_pooled" and r["ball"] == "baseball"]
    assert len(e_x) == 1 and np.isfinite(e_x[0]["value"]) and e_x[0]["uncertainty"] > 0


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


def test_seeds_are_reproducible_and_independent():
    a = [replicate_seeds(7, k) for k in range(200)]
    assert a == [replicate_seeds(7, k) for k in range(200)]
    flat = [s for pair in a for s in pair]
    assert len(set(flat)) == len(flat)  # every experiment and every rendering has its own stream
    assert replicate_seeds(8, 0) != a[0]


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


def test_the_truth_jobs_replicate_skips_what_its_truth_does_not_read(config, balls, bats, monkeypatch):
    """check=False (the truth job): no contact population shifts, eta^2's value not fitted, no bound on mu_k estimated;
    every truth as with them.
    """
    from dataclasses import replace

    dataset = copy.deepcopy(config["datasets"]["synthetic"])
    dataset["synthetic"]["impacts"] = SMALL
    settings = StudySettings.from_config(
        {**config, "studies": {"s": {**config["studies"]["calibration"], "dataset": "synthetic"}}}, "s"
    )
    cs = replicates.chain_settings(settings, dataset, replicate_seeds(settings.seed, 2), check=False)
    assert not (cs.reduce.cross_check or cs.reduce.systematics or cs.reduce.population_shifts)
    lean = run_replicate(settings, dataset, 2, balls, bats, check=False)
    real = replicates.chain_settings

    def with_shifts(*args, **kw):
        out = real(*args, **kw)
        return replace(out, reduce=replace(out.reduce, population_shifts=True))

    monkeypatch.setattr(replicates, "chain_settings", with_shifts)
    full = run_replicate(settings, dataset, 2, balls, bats, check=False)
    assert row_labels(lean) == row_labels(full)
    truths = [(a["truth"], b["truth"]) for a, b in zip(lean, full, strict=True)]
    assert all(a == b or (math.isnan(a) and math.isnan(b)) for a, b in truths), truths
    mu_k = [r for r in lean if r["quantity"] == "mu_k_lower_bound"]
    assert mu_k and all(math.isnan(r["value"]) for r in mu_k)  # not estimated
    eta2 = [r for r in lean if r["quantity"] == "eta2"]
    assert eta2 and all(math.isnan(r["value"]) and math.isfinite(r["truth"]) for r in eta2)
    assert all(
        math.isfinite(r["value"]) for r in run_replicate(settings, dataset, 2, balls, bats) if r["quantity"] == "eta2"
    )
    # the uncertainties differ: the contact population's part is in the full one's only
    e_x = [(a["uncertainty"], b["uncertainty"]) for a, b in zip(lean, full, strict=True) if a["quantity"] == "e_x"]
    assert any(a < b for a, b in e_x), e_x
