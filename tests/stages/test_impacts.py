"""The impacts table (ballbat.stages.impacts): what every source stage writes, owned by no other module, each
stage writing exactly its own table.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from ballbat.stages import fit_ex, implications, ingest, normalize, reconstruct, reduce, render, simulate, stronge
from ballbat.stages.impacts import IMPACT_COORDS, IMPACTS, QUANTITIES, SIMULATED_TRUTH, truth_var
from workflow_helpers import ROOT

MAPLE = ROOT / "config" / "examples" / "maple_impacts.csv"
MAPLE_BATS = ROOT / "config" / "examples" / "maple_bats.csv"


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
    assert set(fit.data_vars) == set(fit_ex.fit_ex_table(True, 0.5, has_scale=True, has_contact=True))
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
