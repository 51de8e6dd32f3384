"""Helpers shared by test modules (no test module imports another): small synthetic experiments,
their rendered tracks, and fake study replicates.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import forked
import numpy as np
import pytest
import xarray as xr
import yaml
from track_files import read_long_csv

from ballbat import cli, league
from ballbat.config_checks import validate_config
from ballbat.kinematics import ImpactFlag
from ballbat.pipeline.config import checked_block
from ballbat.pipeline.crate import JobRecord
from ballbat.pipeline.ncio import write_dataset
from ballbat.pipeline.products import flag_attrs
from ballbat.properties import load_balls, load_bats
from ballbat.stages import fit_ex, normalize, reconstruct, simulate
from ballbat.stages import implications as stage
from ballbat.stages.implications import ImplicationsSettings
from ballbat.stages.implications import run as run_scenario
from ballbat.studies.settings import StudySettings
from ballbat.synthetic import SyntheticSettings
from ballbat.tracks.reduce import reduce_tracks
from ballbat.tracks.render import render_tracks, settings_from_config
from ballbat.units import DEGREE, INCH, MPH, RPM
from workflow_helpers import ROOT

#: A small design (impacts per ball and bat) for the stages' tests.
SMALL = {"baseball": {"wood": 8, "metal_rough": 8}, "softball": {"wood": 8}}

#: The example datasets' folder.
EXAMPLE = ROOT / "config" / "examples"

BALLS = load_balls(ROOT / "config" / "balls.csv")
BATS = load_bats(ROOT / "config" / "bats.csv")


def render_cfg(**over):
    cfg = {
        "cameras": {
            "swing": {"fps": 3000, "m_per_px": 0.00074, "mirror": False, "tee_px": [540, 480], "pixel_noise_px": 0.5},
            "spin": {
                "fps": 1000,
                "m_per_px": 0.00125,
                "mirror": False,
                "tee_px": [600, 480],
                "pre_impact_frames": 5,
                "pixel_noise_px": 0.5,
            },
        },
        "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
        "seed": 1,
        "tilted_fraction": 0.0,
    }
    for k, v in over.items():
        if k in ("swing", "spin"):
            cfg["cameras"][k] = {**cfg["cameras"][k], **v}
        else:
            cfg[k] = v
    return cfg


def experiment(seed=0, per_bat=8):
    settings = SyntheticSettings(
        impacts={"baseball": {"wood": per_bat, "metal_rough": per_bat}, "softball": {"softball_composite": per_bat}},
        e_x={"baseball": {"wood": 0.464, "metal_rough": 0.356}, "softball": {"softball_composite": 0.128}},
        e_y={"baseball": 0.45, "softball": 0.32},
        seed=seed,
        v_bat_mph=(63.0, 88.0),  # the schema's defaults (SyntheticSettings takes every field)
        psi_deg={},
        e_x_scatter=0.0,
        noise={"v_bat_mph": 0.5, "v_ball_mph": 0.5, "theta_deg": 0.5, "omega_rpm": 75.0},
    )
    return simulate.run(settings, BALLS, BATS)


def render(ds, cfg, truth_over=None):
    s = settings_from_config(checked_block(cfg, "render"))  # the schema's defaults, as the workflow's config has them
    truth = {k: ds[f"truth_{k}"].values.copy() for k in ("v_bat", "v_ball", "theta", "omega", "psi")}
    truth.update(truth_over or {})
    r = np.array([BALLS[b].r for b in ds["ball"].values])
    tr = render_tracks(truth, r, s, ds["impact"].values.astype(str), ds["ball"].values, ds["bat"].values)
    return tr, s


def one_long_track(path: Path, factor: int = 5, long: int = 4, seed: int = 3, per_bat: int = 10):
    """Write rendered tracks of 3 x ``per_bat`` impacts as a NetCDF tracks file, one track ``factor`` times as long.

    Impact ``long``'s swing-camera ball track gets ``factor - 1`` times its frames more, at rest
    before its first (its first position, 0.5 px noise): a lab that started tracking early.
    Returns the render settings.
    """
    from ballbat.pipeline.ncio import write_dataset
    from ballbat.stages.render import tracks_dataset

    tr, s = render(experiment(seed, per_bat=per_bat), render_cfg(tilted_fraction=0.2))
    ds = tracks_dataset(tr)
    cols = ("impact_id", "camera", "point", "frame", "x_px", "y_px")
    rows = {k: ds[k].values for k in cols}
    sel = (rows["impact_id"] == tr.impact_id[long]) & (rows["camera"] == "swing") & (rows["point"] == "ball")
    first = np.argmin(np.where(sel, rows["frame"], np.iinfo(np.int64).max))
    k = (factor - 1) * int(sel.sum())
    noise = 0.5 * np.random.default_rng(seed).standard_normal((2, k))
    extra = {
        "impact_id": np.full(k, tr.impact_id[long]),
        "camera": np.full(k, "swing"),
        "point": np.full(k, "ball"),
        "frame": rows["frame"][first] - 1 - np.arange(k),
        "x_px": rows["x_px"][first] + noise[0],
        "y_px": rows["y_px"][first] + noise[1],
    }
    out = ds.drop_dims("row").assign(
        {c: ("row", np.concatenate([rows[c], extra[c]]).astype(rows[c].dtype), ds[c].attrs) for c in cols}
    )
    write_dataset(out, path, title="tracks, one long", rule="test", inputs={}, config={})
    return s


def fake_replicates(n, se, spread, truth=1.0, dof=np.inf, seed=0):
    """Return n replicates of one quantity: estimates truth + N(0, spread) reporting ``se``."""
    rng = np.random.default_rng(seed)
    ds = xr.Dataset(
        {
            "value": (("replicate", "quantity"), truth + spread * rng.standard_normal((n, 1))),
            "uncertainty": (("replicate", "quantity"), np.full((n, 1), se)),
            "truth": (("replicate", "quantity"), np.full((n, 1), truth)),
            "dof": (("replicate", "quantity"), np.full((n, 1), dof)),
            "point": (("replicate",), np.zeros(n, dtype=int)),
        },
        coords={
            "quantity": ["e_x:baseball:wood"],
            "quantity_name": ("quantity", ["e_x"]),
            "ball": ("quantity", ["baseball"]),
            "bat": ("quantity", ["wood"]),
            "units": ("quantity", ["1"]),
        },
        attrs={"sweep_values": np.array([np.nan]), "study_seed": 0, "replicates_per_point": n, "sweep_parameter": ""},
    )
    return ds


#: The installed console script, beside this interpreter.
BALLBAT = Path(sys.executable).parent / "ballbat"


def run_ballbat(*args: str, installed: bool = False, timeout: float = 60) -> subprocess.CompletedProcess:
    """`ballbat ARGS`: the installed command (on this checkout's package), or (the default) a forked process."""
    if not installed:
        return forked.ballbat(*args, cwd=Path.cwd(), timeout=timeout)
    env = {**os.environ, "PYTHONPATH": str(Path(cli.__file__).parents[2])}
    return subprocess.run([str(BALLBAT), *args], capture_output=True, text=True, timeout=timeout, env=env)


def ballbat_in_process(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run `ballbat` as its entry point does (:func:`ballbat.cli.main`), in this process (no start-up cost).

    Its exit status, standard output and error come back as from the installed command; the entry
    point itself is tested through that command (cli/test_app.py, test_entry_point_is_installed).
    """
    out, err = io.StringIO(), io.StringIO()
    here = Path.cwd()
    try:
        if cwd is not None:
            os.chdir(cwd)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = cli.main(list(args))
            except SystemExit as exc:  # argparse: --help, --version and bad arguments
                status = exc.code if isinstance(exc.code, int) else 1
    finally:
        os.chdir(here)
    return subprocess.CompletedProcess(["ballbat", *args], status, out.getvalue(), err.getvalue())


def ballbat_forked(*args: str, installed: bool = False) -> subprocess.CompletedProcess:
    """Run `ballbat ARGS`: the installed command, or (the default) a process forked with its libraries loaded."""
    if not installed:
        return forked.ballbat(*args, cwd=ROOT, timeout=120)
    assert BALLBAT.is_file(), f"{BALLBAT}: the entry point is not installed"
    return subprocess.run([str(BALLBAT), *args], capture_output=True, text=True, cwd=ROOT, timeout=120)


LEAGUE_SOURCES = list(league.SHARING)


def league_fit_file(
    folder: Path, dataset: str, bats: dict, ball: str = "baseball", older: bool = False, sources: list = LEAGUE_SOURCES
) -> Path:
    """Write ``folder/dataset/fit_ex.nc`` with ``bats``: name -> (e_x, stat, n, systematic of ``sources[0]``)."""
    names = list(bats)
    shape = (1, len(names))
    val = {k: np.array([[bats[b][i] for b in names]], dtype=float) for i, k in enumerate(("e_x", "err", "n", "s"))}
    per = np.zeros((len(sources), *shape))
    per[0] = val["s"]
    one = {"units": "1", "long_name": "x"}
    ds = xr.Dataset(
        {
            "e_x": (("ball", "bat"), val["e_x"], one),
            "e_x_err": (("ball", "bat"), val["err"], one),
            "e_x_n": (("ball", "bat"), val["n"].astype(np.int64), one),
            "e_x_status": (("ball", "bat"), np.zeros(shape, dtype=np.int8), one),
            "e_x_scatter": (("ball", "bat"), np.zeros(shape), one),
            "e_x_syst_by_source": (("systematic", "ball", "bat"), per, one),
        },
        coords={
            "ball": ("ball", np.array([ball]), {"long_name": "ball"}),
            "bat": ("bat", np.array(names), {"long_name": "bat"}),
            "systematic": ("systematic", np.array(sources), {"long_name": "source"}),
        },
    )
    if older:  # fit_ex.nc before the intrinsic scatter (issue 36) and the systematics by source
        ds = ds.drop_vars(["e_x_scatter", "e_x_syst_by_source", "systematic"])
        ds["e_x_err_scale"] = (("ball", "bat"), val["s"], one)
    path = folder / dataset / "fit_ex.nc"
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_dataset(ds, path, title="test fit_ex", rule="fit_ex", inputs={}, config={})


def league_settings(**kw) -> league.LeagueSettings:
    return league.LeagueSettings.from_config({"league": kw})


def league_pair(ds: xr.Dataset, a: str, b: str) -> dict:
    i = next(
        i for i in range(ds.sizes["pair"]) if {str(ds.pair_bat_a[i].values), str(ds.pair_bat_b[i].values)} == {a, b}
    )
    return {k.removeprefix("pair_"): ds[k].values[i] for k in ds.data_vars if ds[k].dims == ("pair",)}


def league_row(ds: xr.Dataset, bat: str) -> dict:
    i = int(np.flatnonzero(ds["bat"].values == bat)[0])
    return {k: ds[k].values[i] for k in ds.data_vars if ds[k].dims == ("row",)}


WORKBOOK_PROVENANCE = {
    "provenance_rule": "reconstruct",
    "provenance_inputs": json.dumps([{"name": "normalize", "path": "results/t/normalize.nc", "sha256": "ab12"}]),
    "provenance_config": json.dumps({"v_ref_mph": 77.0}),
    "provenance_software": json.dumps({"ballbat": "9.9"}),
    "provenance_git": json.dumps({"commit": "unknown", "dirty": False}),
}


def workbook_impacts() -> xr.Dataset:
    """Three impacts as reconstruct.nc holds them (SI), one with a missing spin and one flagged."""
    n = 3
    return xr.Dataset(
        {
            "impact_id": ("impact", np.array(["A1", "A2", "A3"])),
            "ball": ("impact", np.array(["baseball", "baseball", "softball"])),
            "bat": ("impact", np.array(["wood", "wood", "metal"])),
            "v_bat": ("impact", np.array([70.0, 75.0, 80.0]) * MPH),
            "v_bat_err": ("impact", np.array([0.5, 0.5, 0.25]) * MPH),
            "theta": ("impact", np.array([10.0, -5.5, 20.25]) * DEGREE),
            "omega": ("impact", np.array([1900.0, np.nan, 2500.4]) * RPM),
            "D": ("impact", np.array([0.5, 1.25, -0.75]) * INCH),
            "r_x": ("impact", np.full(n, 0.2)),
            "flag": ("impact", np.array([0, 0, 4], dtype=np.int8), flag_attrs(ImpactFlag)),
            "flag_reason": ("impact", np.array(["ok", "ok", "excluded at ingest"])),
        },
        coords={"impact": ("impact", np.arange(n))},
        attrs={**WORKBOOK_PROVENANCE, "title": "reconstruct", "ingest_warnings": "first warning\nsecond warning\n"},
    )


def sheet_rows(ws) -> list[list]:
    return [[c.value for c in row] for row in ws.iter_rows()]


def pilot_fit(se: dict, n: dict) -> xr.Dataset:
    bats = list(se)
    one, shape = {"units": "1", "long_name": "x"}, (1, len(bats))
    return xr.Dataset(
        {
            "e_x": (("ball", "bat"), np.full(shape, 0.45), one),
            "e_x_err": (("ball", "bat"), [[se[b] for b in bats]], one),
            "e_x_n": (("ball", "bat"), [[n[b] for b in bats]], one),
            "e_x_status": (("ball", "bat"), np.zeros(shape, dtype=np.int8), one),
            "e_x_scatter": (("ball", "bat"), np.zeros(shape), one),
        },
        coords={"ball": ("ball", ["baseball"], {"long_name": "b"}), "bat": ("bat", bats, {"long_name": "b"})},
    )


def product_file(path: Path) -> Path:
    """A NetCDF file as the workflow writes it (with its provenance record)."""
    ds = xr.Dataset(
        {"x": ("n", np.linspace(0.0, 1.0, 500), {"units": "m", "long_name": "a length"})},
        coords={"n": ("n", np.arange(500), {"units": "1", "long_name": "index"})},
    )
    return write_dataset(ds, path, title="t", rule="r", inputs={}, config={})


def users_netcdf4(path: Path) -> Path:
    """A whole NetCDF-4 file of the user's (no provenance record)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    xr.Dataset({"y": ("k", np.arange(10.0))}).to_netcdf(path, format="NETCDF4", engine="netcdf4")
    return path


def crate_netcdf(path, note):
    """A small NetCDF file carrying the workflow's provenance mark."""
    import xarray as xr

    path.parent.mkdir(parents=True, exist_ok=True)
    attrs = {"provenance_rule": "r", "provenance_config": json.dumps({"note": note}), "note": note}
    xr.Dataset({"x": ("n", [1.0])}, attrs=attrs).to_netcdf(path, engine="netcdf4")


def crate_ids(value):
    refs = value if isinstance(value, list) else [value]
    return sorted(r["@id"] for r in refs)


def crate_graph(results):
    doc = json.loads((results / "ro-crate-metadata.json").read_text())
    return {e["@id"]: e for e in doc["@graph"]}


def crate_folder(tmp_path):
    """A results folder with one job's NetCDF output (with a provenance mark), its log, and an input."""
    (tmp_path / "Snakefile").write_text("# the workflow\n")
    (tmp_path / "config").mkdir()
    (tmp_path / "config" / "in.csv").write_text("a,b\n1,2\n")
    results = tmp_path / "results"
    (results / "logs").mkdir(parents=True)
    crate_netcdf(results / "a.nc", "a")
    (results / "logs" / "a.log").write_text("log\n")
    job = JobRecord(
        rule="r", wildcards={}, inputs=["config/in.csv"], outputs=["results/a.nc"], logs=["results/logs/a.log"]
    )
    return results, job


def study_settings(config, name="calibration", **over):
    """The settings of study ``name`` of ``config`` with the values ``over`` changed."""
    cfg = copy.deepcopy(config)
    cfg["studies"][name].update(over)
    return StudySettings.from_config(cfg, name)


def unbalanced(config, **over):
    cfg = copy.deepcopy(config)
    cfg["datasets"]["synthetic"]["synthetic"]["impacts"] = copy.deepcopy(UNBALANCED)
    cfg["studies"]["calibration"].update(over)
    return cfg


#: The unbalanced design of issue 40: 6 impacts on some bats and 60 on others, the softball bat
#: swung with softballs only (102 of the 204 impacts on three pairs of 60).
UNBALANCED = {
    "baseball": {"wood": 6, "metal_rough": 60, "metal_smooth": 6},
    "softball": {"wood": 60, "metal_rough": 6, "metal_smooth": 60, "softball_composite": 6},
}


def write_table(path: Path, head: str, row: str) -> Path:
    path.write_text(f"{head}\n{row}\n")
    return path


HICKORY_HEAD = (
    "bat,name,convention,length_in,weight_oz,balance_in,pivot_in,moi_oz_in2,impact_from_tip_in,diameter_in,Iz_oz_in2"
)


def reduce_tracks_of(tr, s, **cams):
    cameras = {"swing": s.swing.camera, "spin": s.spin.camera}
    cameras.update(cams)
    return reduce_tracks(tr, cameras, s.rig)


NORM = normalize.NormalizeSettings(v_ref_mph=77.0)


REC = reconstruct.ReconstructSettings()


FIT = fit_ex.FitExSettings(mu_k_example=0.5, systematic=True, check_physical=True, mu_k_bound=True)


def fit_chain(settings, balls, bats, **over):
    s = SyntheticSettings(**{**settings, **over})
    return fit_ex.run(FIT, reconstruct.run(REC, normalize.run(NORM, simulate.run(s, balls, bats)), balls, bats))


HICKORY_BATS = ROOT / "config" / "examples" / "hickory_bats.csv"


SWEEP = {"pitch_mph": 90, "pitch_descent_deg": 6, "pitch_backspin_rpm": 2000, "bat_mph": 70, "attack_deg": 6}


def scenario_settings(tables, **sweep) -> stage.ImplicationsSettings:
    sweep = {"D_in": {"start": 0.0, "stop": 1.0, "num": 3}, **sweep}
    block = {"ball": "baseball", "bat": "hickory", "sweep": {**SWEEP, **sweep}}
    imp = checked_block({"scenarios": {"s": block}}, "implications")
    return stage.ImplicationsSettings(scenario=imp["scenarios"]["s"], air=imp["air"])


def same_tracks(got, want, tol=0.0):
    assert set(got) == set(want)
    for name, (f, x, y) in want.items():
        gf, gx, gy = got[name]
        np.testing.assert_array_equal(gf - gf.min(), f - f.min())
        np.testing.assert_allclose(gx - gx[0], x - x[0], atol=tol, rtol=0)
        np.testing.assert_allclose(gy - gy[0], y - y[0], atol=tol, rtol=0)


@pytest.fixture(scope="module")
def tables():
    return load_balls(ROOT / "config" / "balls.csv"), load_bats(HICKORY_BATS)


@pytest.fixture(scope="module")
def cfg(config):
    return config["implications"]


@pytest.fixture(scope="module")
def complete(config, root):
    """A scenario as the workflow sees it: checked against the schema, its defaults filled."""
    schema = yaml.safe_load((root / "workflow" / "schemas" / "config.schema.yaml").read_text())

    def fill(sc):
        cfg = copy.deepcopy(config)
        cfg["implications"]["scenarios"] = {"s": sc}
        return validate_config(cfg, schema)["implications"]["scenarios"]["s"]

    return fill


@pytest.fixture(scope="module")
def paper(cfg, balls, bats):
    return run_scenario(ImplicationsSettings(cfg["scenarios"]["paper"], cfg["air"]), balls, bats)


@pytest.fixture(scope="module")
def rows():
    return read_long_csv(EXAMPLE / "tracked_tracks.csv")


def assert_cases_have_tests(cases: dict, module_globals: dict) -> None:
    """Check a red-team table: every case names its outcome and tests of the module (``globals()``) that exist."""
    names = {name for name, obj in module_globals.items() if name.startswith("test_") and callable(obj)}
    for case, (outcome, tests) in cases.items():
        assert outcome and tests and set(tests) <= names, case
