"""One chain (issue 33): the chain in memory gives the workflow's files, for every kind of source."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import xarray as xr
import yaml

from ballbat import chain
from ballbat.config_checks import validate_config
from ballbat.pipeline.config import packaged_schema
from ballbat.properties import load_balls, load_bats
from ballbat.tracks.io import load_tracks


def _config(work, extra: str | None = None) -> dict:
    cfg = yaml.safe_load((work / "config" / "config.yaml").read_text())
    if extra:
        cfg["datasets"].update(yaml.safe_load((work / extra).read_text())["datasets"])
    return validate_config(cfg, packaged_schema(), available=64 * 2**30)


def _same(memory: xr.Dataset, path, rtol: float = 0.0) -> None:
    """Every data variable of the file, value for value (floats within ``rtol``), in the Dataset made in memory.

    A systematic (``*_syst*``) is half the difference of two fits, so its round-off is its quantity's:
    within ``rtol`` of that quantity's largest value (6e-7 of a 2.8e-4 systematic seen on an AMD EPYC).
    """
    with xr.open_dataset(path) as ds:
        names = [k for k in ds.data_vars if not k.endswith("_shift")]
        assert names, path
        for k in names:
            assert k in memory, f"{path.name}: {k} not made by the chain"
            a, b = memory[k].values, ds[k].values
            if a.dtype.kind in "fc":
                base = k.split("_syst")[0]
                scale = np.nanmax(np.abs(ds[base].values)) if "_syst" in k and base in ds else 0.0
                np.testing.assert_allclose(a, b, rtol=rtol, atol=rtol * scale, err_msg=f"{path.name}: {k}")
            else:
                assert a.astype(str).tolist() == b.astype(str).tolist(), f"{path.name}: {k}"


@pytest.mark.slow
def test_a_rendered_dataset(default_run, monkeypatch):
    """The default dataset: simulate, render and reduce in memory, then the fits: reduce.nc and fit_ex.nc."""
    monkeypatch.chdir(default_run)
    settings = chain.DatasetSettings.from_config(_config(default_run), "synthetic")
    assert settings.render is not None and settings.reduce is not None and settings.reduce.systematics
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    src = chain.source(settings, balls, bats)
    res = default_run / "results" / "synthetic"
    # the workflow's tracks go through tracks.nc and are laid out again from its long table (each
    # track from its first tracked frame): times differ at round-off (3e-12 s, 1e-8 of a frame)
    _same(src, res / "reduce.nc", rtol=1e-7)
    out = chain.run(settings, src, balls, bats)
    _same(out.reconstruct, res / "reconstruct.nc", rtol=1e-7)
    _same(out.fit_ex, res / "fit_ex.nc", rtol=1e-7)


@pytest.mark.slow
def test_a_measured_file_and_a_tracks_file(lab_run, monkeypatch):
    """Maple's impacts file (ingest) and the tracked example's tracks file (reduce), as the lab run made them."""
    monkeypatch.chdir(lab_run)
    cfg = _config(lab_run)
    maple = chain.DatasetSettings.from_config(cfg, "maple")
    assert maple.synthetic is None and maple.reduce is None
    block = cfg["datasets"]["maple"]
    tables = {k: block.get(k, cfg["tables"][k]) for k in ("balls", "bats")}
    src = chain.ingest(block["impacts"], tables["balls"], tables["bats"])
    res = lab_run / "results"
    _same(src, res / "maple" / "ingest.nc")
    fit = chain.run(maple, src, load_balls(tables["balls"]), load_bats(tables["bats"])).fit_ex
    _same(fit, res / "maple" / "fit_ex.nc")

    cfg = _config(lab_run, "tools.yaml")
    tracked = chain.DatasetSettings.from_config(cfg, "tracked")
    balls, bats = load_balls(cfg["tables"]["balls"]), load_bats(cfg["tables"]["bats"])
    block = cfg["datasets"]["tracked"]["tracks"]
    tracks = load_tracks(block["file"], block["impacts"], balls, bats)
    src = chain.source(tracked, balls, bats, tracks=tracks, source_file=block["file"])
    _same(src, res / "tracked" / "reduce.nc")
    _same(chain.run(tracked, src, balls, bats).fit_ex, res / "tracked" / "fit_ex.nc")


@pytest.mark.slow
def test_a_folder_of_tracker_files(lab_run, monkeypatch):
    """The lab run's ``trk`` dataset (a folder of Tracker projects): the chain in memory, and ``ballbat check``'s
    reduction of the same block, give the workflow's reduce.nc (import_tracks, then reduce) and fit_ex.nc.
    """
    from ballbat.stages import reduce
    from ballbat.tracks.data import camera_block, with_found_settings
    from ballbat.tracks.formats.layout import import_block

    monkeypatch.chdir(lab_run)
    cfg = _config(lab_run, "tools.yaml")
    balls, bats = load_balls(cfg["tables"]["balls"]), load_bats(cfg["tables"]["bats"])
    block = cfg["datasets"]["trk"]["tracks"]
    res = lab_run / "results" / "trk"
    tracks, imported = import_block(block, "datasets.trk.tracks", balls, bats)
    found = with_found_settings(camera_block(block), imported.settings_yaml())
    settings = chain.DatasetSettings.from_config(cfg, "trk")
    settings = dataclasses.replace(
        settings, reduce=reduce.ReduceSettings.from_config(found, "datasets.trk.tracks", systematics=True)
    )
    # exactly: the import's tracks file keeps every digit of the pixels
    src = chain.source(settings, balls, bats, tracks=tracks)
    _same(src, res / "reduce.nc")
    _same(chain.run(settings, src, balls, bats).fit_ex, res / "fit_ex.nc")
    red, verdict = chain.reduce_tracks_block(block, "datasets.trk.tracks", balls, bats)  # ballbat check's
    checked = reduce.reduction_dataset(red)
    with xr.open_dataset(res / "reduce.nc") as ds:  # a check runs no calibration reruns: no systematic's variables
        syst = {k for k in ds.data_vars if "systematic" in ds[k].dims or k.startswith("systematic")}
    assert syst and not syst & set(checked.data_vars)
    _same(checked.assign({k: src[k] for k in syst}), res / "reduce.nc")
    assert verdict.lines and "\n".join(verdict.lines) == src.attrs["reduce_checks"]
