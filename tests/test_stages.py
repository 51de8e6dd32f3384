"""The stage layer (src/ballbat/stages/): each stage's run on small in-memory inputs.

Each stage writes exactly its declared table, the source stages share the one impacts table,
a stage gives the numbers of the compute functions it calls, its settings come from the
validated config, the rule scripts are one call of a stage, and a replicate of the studies is
those same calls.
"""

from __future__ import annotations

import copy
import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
from helpers import SMALL

from ballbat import fitting
from ballbat.stages import fit_ex, implications, ingest, normalize, reconstruct, reduce, render, simulate, stronge
from ballbat.stages.impacts import IMPACT_COORDS, IMPACTS, QUANTITIES, SIMULATED_TRUTH, truth_var
from ballbat.studies import replicates
from ballbat.studies.replicates import STUDY_QUANTITIES, run_replicate
from ballbat.studies.settings import StudySettings
from ballbat.synthetic import SyntheticSettings
from ballbat.tracks.data import camera_block
from ballbat.tracks.render import settings_from_config
from workflow_helpers import ROOT

MAPLE = ROOT / "config" / "examples" / "maple_impacts.csv"
MAPLE_BATS = ROOT / "config" / "examples" / "maple_bats.csv"


@pytest.fixture(scope="module")
def chain(config, balls, bats):
    """A small synthetic dataset through simulate, render, reduce, normalize, reconstruct (the workflow's settings)."""
    synth = simulate.from_config(config, "synthetic")
    sim = simulate.run(dataclasses.replace(synth, impacts=SMALL), balls, bats)
    rset = render.from_config(config, "synthetic")
    tracks = render.render(rset, sim, balls)
    rs = reduce.ReduceSettings.from_config(
        camera_block(config["datasets"]["synthetic"]["render"]), "render", systematics=False
    )
    red = reduce.run(rs, tracks, balls, bats)
    norm = normalize.run(normalize.NormalizeSettings.from_config(config), sim)
    rec = reconstruct.run(reconstruct.ReconstructSettings.from_config(config), norm, balls, bats)
    red_rec = reconstruct.run(
        reconstruct.ReconstructSettings(), normalize.run(normalize.NormalizeSettings(77.0), red), balls, bats
    )
    return {"sim": sim, "tracks": tracks, "rset": rset, "red": red, "norm": norm, "rec": rec, "red_rec": red_rec}


# ---------------------------------------------------------------------------------------
# the one impacts table


def test_impacts_table_is_what_every_source_stage_writes(chain, balls, bats):
    """simulate.nc, ingest.nc and reduce.nc declare their measurements from the one IMPACTS table."""
    ing = ingest.run(ingest.IngestSettings(calibration={}), MAPLE, ROOT / "config" / "balls.csv", MAPLE_BATS)
    for name, ds in (("simulate", chain["sim"]), ("ingest", ing), ("reduce", chain["red"])):
        for k in QUANTITIES:
            for var in (k, f"{k}_err"):
                want = IMPACTS[var]
                got = ds[var].attrs
                assert got["units"] == want.units, (name, var)
                assert got["ballbat_role"] == want.attrs["ballbat_role"], (name, var)
                assert got["long_name"].startswith(want.long_name), (name, var)
        for c in ("ball", "bat"):
            assert ds[c].attrs["long_name"] == IMPACT_COORDS[c].long_name, (name, c)
        assert ds["impact"].attrs["units"] == "1" and ds["impact"].attrs["long_name"] == "impact number"
    # simulate.nc is the table exactly; the truth of the measured quantities is declared alike
    assert {k: chain["sim"][k].attrs for k in IMPACTS} == {k: v.attributes() for k, v in IMPACTS.items()}
    for k in QUANTITIES:
        assert truth_var(f"truth_{k}").units == IMPACTS[k].units
    assert chain["red"]["truth_psi"].attrs == chain["sim"]["truth_psi"].attrs == truth_var("truth_psi").attributes()


def test_no_second_owner_of_the_impacts_table():
    """The compute modules that once declared the measurements no longer do (issue 20: four owners)."""
    import ballbat.ingest
    import ballbat.synthetic
    import ballbat.tracks.io
    import ballbat.tracks.reduce

    for mod in (ballbat.ingest, ballbat.synthetic, ballbat.tracks.io, ballbat.tracks.reduce):
        text = Path(mod.__file__).read_text()
        assert "exit speed of the ball" not in text, mod.__name__
        assert "true impact angle psi" not in text, mod.__name__


# ---------------------------------------------------------------------------------------
# each stage writes exactly its table


def test_each_stage_writes_exactly_its_table(chain, config, balls, bats):
    sim, norm, rec, red = chain["sim"], chain["norm"], chain["rec"], chain["red"]
    assert set(sim.data_vars) == set(simulate.simulate_table())
    assert set(norm.data_vars) - set(sim.data_vars) == set(normalize.NORMALIZE_TABLE)
    assert set(rec.data_vars) - set(norm.data_vars) == set(reconstruct.RECONSTRUCT_TABLE)
    assert norm.attrs["v_ref"] == pytest.approx(config["normalize"]["v_ref_mph"] * 0.44704)
    truth = sorted(k for k in red.data_vars if k.startswith("truth_"))
    assert set(red.data_vars) == set(reduce.reduction_table(truth))
    assert {f"truth_{k}" for k in SIMULATED_TRUTH} <= set(truth)
    tracks_ds = render.tracks_dataset(chain["tracks"])
    assert set(tracks_ds.data_vars) == set(render.TRACKS_TABLE) | set(chain["tracks"].truth)
    fit = fit_ex.run(fit_ex.FitExSettings.from_config(config), chain["red_rec"])
    assert set(fit.data_vars) == set(fit_ex.fit_ex_table(True, 0.5, has_scale=True))
    st = stronge.run(stronge.StrongeSettings(**{**config["stronge"], "n_time": 40}), rec)
    assert set(st.data_vars) == set(stronge.stronge_variables())
    assert set(st.coords) == set(stronge.STRONGE_COORDS)
    ing = ingest.run(ingest.IngestSettings(calibration={}), MAPLE, ROOT / "config" / "balls.csv", MAPLE_BATS)
    assert set(ing.data_vars) <= set(ingest.INGEST_TABLE)
    assert set(ingest.INGEST_TABLE) - set(ing.data_vars) == {"theta_err", "v_bat_err", "v_ball_err"} - set(ing)
    sc = implications.ImplicationsSettings.from_config(config, "paper")
    sweep = {**sc.scenario["sweep"], "D_in": {"start": -1.0, "stop": 1.0, "num": 3}}
    sc = dataclasses.replace(sc, scenario={**sc.scenario, "sweep": sweep})
    impl = implications.run(sc, balls, bats)
    assert list(impl.data_vars) == list(implications.scenario_table(True, sc.scenario["mu"]))
    assert impl.sizes["case"] == 3


# ---------------------------------------------------------------------------------------
# the stages give the compute functions' numbers


def test_fit_ex_stage_gives_the_compute_functions_numbers(chain, config):
    """fit_ex.run on a tiny reduced set: its values are those of fitting.analyze_impacts, nothing lost or added."""
    rec = chain["red_rec"]
    res = fitting.analyze_impacts(rec, 0.5)
    fit = fit_ex.run(fit_ex.FitExSettings.from_config(config), rec)
    np.testing.assert_array_equal(fit["e_x"].values, res.e_x.field("slope", -1.0))
    np.testing.assert_array_equal(fit["e_x_err"].values, res.e_x.field("slope_err"))
    np.testing.assert_array_equal(fit["e_x_pooled"].values, res.e_x_pooled.field("slope", -1.0))
    np.testing.assert_array_equal(fit["tan_ratio_slope"].values, res.tan_ratio_slope.field("slope"))
    np.testing.assert_array_equal(fit["e_y_implied"].values, res.per_ball["e_y_implied"])
    np.testing.assert_array_equal(fit["e_x_err_scale"].values, res.systematic["e_x_err_scale"])
    assert list(fit["ball"].values) == res.balls and list(fit["bat"].values) == res.bats
    assert np.isfinite(fit["e_x_pooled"].values).all()
    assert fit.attrs["n_impacts"] == rec.sizes["impact"]
    assert fit.attrs["n_excluded"] == int((rec["flag"].values != 0).sum())
    assert fit.attrs["v_ref"] == rec.attrs["v_ref"] and fit.attrs["mu_k_example"] == 0.5
    # without the systematic (the studies): no *_err_scale, the same fits
    quiet = fit_ex.run(fit_ex.FitExSettings(0.5, systematic=False, check_physical=True), rec)
    assert "e_x_err_scale" not in quiet
    np.testing.assert_array_equal(quiet["e_x"].values, fit["e_x"].values)


def test_fit_ex_stage_refuses_an_impossible_e_x_unless_told(chain):
    """Spin of the wrong sign gives e_x < -1: an error of the dataset; the studies record it as it comes."""
    flipped = chain["norm"].copy()
    flipped["omega"] = -flipped["omega"]
    rec = reconstruct.run(reconstruct.ReconstructSettings(), flipped, *_tables())
    with pytest.raises(fitting.ImplausibleFit, match="outside the physical range"):
        fit_ex.run(fit_ex.FitExSettings(0.5, systematic=False, check_physical=True), rec)
    fit = fit_ex.run(fit_ex.FitExSettings(0.5, systematic=False, check_physical=False), rec)
    assert np.nanmin(fit["e_x_pooled"].values) < -1


def _tables():
    from ballbat.properties import load_balls, load_bats

    return load_balls(ROOT / "config" / "balls.csv"), load_bats(ROOT / "config" / "bats.csv")


def test_reduce_stage_is_the_reduction_and_its_cross_checks(chain, config):
    """reduce.run: the reduced values of reduce_tracks, the cross-checks' figures as attributes, exclusions listed."""
    from ballbat.tracks.reduce import reduce_tracks

    rs = reduce.ReduceSettings.from_config(
        camera_block(config["datasets"]["synthetic"]["render"]), "render", systematics=False
    )
    red = reduce_tracks(chain["tracks"], rs.cameras, rs.rig, rs.options)
    ds = chain["red"]
    for k in ("v_bat", "v_ball", "theta", "omega", "omega_err"):
        np.testing.assert_array_equal(ds[k].values, red.values[k])
    np.testing.assert_array_equal(ds["ingest_flag"].values, red.flag)
    assert ds.attrs["reduce_checks"].count("\n") >= 1 and "source_file" not in ds.attrs
    assert len(reduce.excluded_listing(ds)) == int((red.flag != 0).sum())


def test_ingest_stage_keeps_warnings_and_exclusions():
    ds = ingest.run(ingest.IngestSettings(calibration={}), MAPLE, ROOT / "config" / "balls.csv", MAPLE_BATS)
    assert ds.attrs["n_warnings"] == len(ingest.warnings(ds)) == 0
    assert ds.attrs["n_excluded"] == 1 and ds.sizes["impact"] == 31
    assert ingest.excluded_listing(ds)[0].startswith("impact MP31 (row 32):")
    assert ds.attrs["source_file"] == str(MAPLE)


# ---------------------------------------------------------------------------------------
# settings


NEW_SETTINGS = (
    fit_ex.FitExSettings,
    normalize.NormalizeSettings,
    reconstruct.ReconstructSettings,
    stronge.StrongeSettings,
    reduce.ReduceSettings,
    ingest.IngestSettings,
    implications.ImplicationsSettings,
)


@pytest.mark.parametrize("cls", NEW_SETTINGS, ids=lambda c: c.__name__)
def test_stage_settings_are_frozen_and_have_no_code_defaults(cls):
    """Values come from the validated config alone (defaults live in the schema)."""
    assert cls.__dataclass_params__.frozen
    for f in dataclasses.fields(cls):
        assert f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING, f.name


def test_settings_from_the_validated_config(config):
    assert fit_ex.FitExSettings.from_config(config) == fit_ex.FitExSettings(
        config["analysis"]["mu_k_example"], systematic=True, check_physical=True
    )
    assert normalize.NormalizeSettings.from_config(config).v_ref_mph == config["normalize"]["v_ref_mph"]
    assert dataclasses.asdict(stronge.StrongeSettings.from_config(config)) == config["stronge"]
    block = config["datasets"]["synthetic"]["render"]
    rs = reduce.ReduceSettings.from_config(camera_block(block), "render", systematics=False)
    assert rs.cameras["swing"].fps == block["cameras"]["swing"]["fps"]
    assert rs.rig.pivot_to_impact == pytest.approx(block["rig"]["pivot_to_impact_in"] * 0.0254)
    assert simulate.from_config(config, "synthetic") == SyntheticSettings(
        **config["datasets"]["synthetic"]["synthetic"]
    )
    assert render.from_config(config, "synthetic") == settings_from_config(block)
    with pytest.raises(dataclasses.FrozenInstanceError):
        normalize.NormalizeSettings(77.0).v_ref_mph = 80.0  # type: ignore[misc]


def test_reduce_settings_name_a_wrong_block():
    from ballbat.properties import InputError

    with pytest.raises(InputError, match=r"config datasets\.x\.tracks"):
        reduce.ReduceSettings.from_config({"cameras": {}, "rig": {}}, "config datasets.x.tracks", systematics=False)


# ---------------------------------------------------------------------------------------
# the rule scripts and the studies call the stages


SCRIPTS = {
    "simulate": "simulate",
    "ingest": "ingest",
    "render_tracks": "render",
    "reduce": "reduce",
    "normalize": "normalize",
    "reconstruct": "reconstruct",
    "fit_ex": "fit_ex",
    "fit_stronge": "stronge",
    "implications": "implications",
    "study_batch": "batch",  # beside the studies (ballbat.studies.batch), not a stage of the chain
}


@pytest.mark.parametrize(("script", "stage"), SCRIPTS.items())
def test_rule_script_is_one_call_of_its_stage(script, stage):
    text = (ROOT / "workflow" / "scripts" / f"{script}.py").read_text()
    package = "ballbat.studies" if script == "study_batch" else "ballbat.stages"
    assert f"from {package} import {stage}" in text
    assert len(re.findall(rf"\b{stage}\.run\(", text)) == 1
    assert "build_dataset" not in text and "xr.Dataset(" not in text


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
