"""A folder of clips through the workflow (docs/video.md, "In the workflow"): tracked on import, then reduced."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from video_clips import LAB_CAMERAS, LAB_RIG, LAB_TRUTH

from ballbat.units import DEGREE, MPH, RPM
from workflow_helpers import assert_not_blank, make_workdir, planned_logs, snakemake, write_config


@pytest.mark.slow
def test_a_folder_of_clips_is_tracked_and_reduced_to_its_impacts(tmp_path, lab_clips):
    """Two batches of three clips (track_clips), gathered and reduced; a clip filmed again reruns its batch only."""
    import shutil

    import xarray as xr

    wd = make_workdir(tmp_path)
    shutil.copytree(lab_clips[0], wd / "lab" / "clips")
    block = {
        "dir": "lab/clips",
        "format": "video",
        "impacts": "lab/clips/impacts.csv",
        "cameras": {c: {"m_per_px": v["m_per_px"], "mirror": False} for c, v in LAB_CAMERAS.items()},
        "rig": LAB_RIG,
        "video": {"dot_radius_mm": 4.0, "marker_radius_mm": 6.0, "clips_per_job": 3},
    }
    write_config(wd, lambda cfg: cfg["datasets"].update(vid={"tracks": block}))
    snakemake(wd, "-c2", "--", "results/vid/reduce.nc")
    found = yaml.safe_load((wd / "results" / "vid" / "imported_cameras.yaml").read_text())
    assert found["files"] == 6 and found["cameras"]["swing"]["fps"] == 3000.0  # the frame rate from the clips
    assert found["cameras"]["swing"]["exposure_us"] == pytest.approx(50.0)  # and the exposure
    assert (wd / "results" / "vid" / "imported_quality.nc").is_file()  # import_clips: the tracker's quality kept
    red = xr.open_dataset(wd / "results" / "vid" / "reduce.nc")
    assert list(red["impact_id"].values) == ["W1", "W2", "W3"]
    # the clips' true impacts, within a few of the reduction's own standard errors (SI units)
    unit = {"v_bat": MPH, "v_ball": MPH, "theta": DEGREE, "omega": RPM}
    for name, u in unit.items():
        got, err = red[name].values, red[f"{name}_err"].values
        assert np.all(np.abs(got - LAB_TRUTH[name] * u) < 4 * err), (name, got / u, err / u)
    # batch 0: W1_spin, W1_swing, W2_spin; batch 1: W2_swing, W3_spin, W3_swing. W3_spin's new content
    # (bytes after the TIFF's frames: the same frames) reruns batch 1, then the import and the reduction.
    with open(wd / "lab" / "clips" / "W3_spin.tif", "ab") as fh:
        fh.write(b"filmed again")
    jobs = planned_logs(wd, "--", "results/vid/reduce.nc")
    assert sorted(jobs.values()) == ["import_clips", "reduce", "track_clips"], jobs
    assert "results/vid/logs/track_clips_1.log" in jobs


@pytest.mark.slow
def test_a_filmed_experiment_is_drawn_tracked_and_reduced_from_its_pixels(tmp_path):
    """render.video: the clips drawn (render_clips), tracked in two batches (track_clips), gathered
    (import_clips) and reduced: within 4 standard errors of the experiment's truth; the folder of clips is
    written whole, and a rerun does nothing. The tracker's quality is kept (imported_quality.nc, in the
    run's crate) and drawn (clips_quality.png). The gathered files are those of one job tracking every clip.
    """
    import json

    import xarray as xr

    wd = make_workdir(tmp_path)
    example = yaml.safe_load((wd / "config" / "examples" / "video.yaml").read_text())["datasets"]["video"]
    example["synthetic"]["impacts"] = {"baseball": {"wood": 4}}
    example["synthetic"]["e_x"] = {"baseball": {"wood": 0.464}}
    # TIFF stacks rather than the example's FFV1: the same chain, without FFV1's slow decoding (76
    # frames a second of CPU); writing and reading FFV1 are tested in tests/video and tests/stages
    example["render"]["video"]["format"] = "tif"
    example["render"]["video"]["clips_per_job"] = 4  # 8 clips: two batches, side by side
    write_config(wd, lambda cfg: cfg["datasets"].update(filmed=example))
    sheet = "results/filmed/figures/clips_contact_sheet.png"
    quality = "results/filmed/figures/clips_quality.png"
    snakemake(wd, "-c2", "--", "results/filmed/reduce.nc", sheet, quality)
    res = wd / "results" / "filmed"
    assert_not_blank(wd / sheet)
    assert_not_blank(wd / quality)
    q = xr.open_dataset(res / "imported_quality.nc")
    assert q.attrs["provenance_rule"] == "import_clips" and q.attrs["n_clips"] == 8
    assert q["residual_px"].attrs["units"] == "1" and q.attrs["n_found"] > 0 and q.attrs["n_left_out"] > 0
    tracked = xr.open_dataset(res / "imported_tracks.nc")
    assert q.attrs["n_found"] == tracked.attrs["n_rows"]  # every point found is a row of the tracks
    crate = json.loads((wd / "results" / "ro-crate-metadata.json").read_text())
    made = [e for e in crate["@graph"] if e["@id"].endswith("filmed/imported_quality.nc")]
    assert made and "File" in made[0]["@type"]
    batches = sorted(p.name for p in (res / "clip_tracks").iterdir())
    assert batches == ["batch_0.nc", "batch_1.nc"]
    for name in batches:  # each batch file in the crate, made by its own track_clips job
        entity = [e for e in crate["@graph"] if e["@id"].endswith(f"filmed/clip_tracks/{name}")]
        assert entity and "File" in entity[0]["@type"]
        batch = xr.open_dataset(res / "clip_tracks" / name)
        assert batch.attrs["provenance_rule"] == "track_clips" and batch["clip_fps"].attrs["units"] == "Hz"
        assert batch["clip_exposure"].attrs["units"] == "s" and np.allclose(batch["clip_exposure"].values, 50e-6)
    assert [xr.open_dataset(res / "clip_tracks" / n).sizes["clip"] for n in batches] == [4, 4]
    _same_as_one_job(wd, res)
    names = sorted(p.name for p in (res / "clips").iterdir())
    assert len([n for n in names if n.endswith(".tif")]) == 8 and "impacts.csv" in names
    assert not [p for p in res.iterdir() if p.name.startswith(".clips.")]  # no temporary folder left
    truth = xr.open_dataset(res / "simulate.nc")
    red = xr.open_dataset(res / "reduce.nc")
    assert list(red["impact_id"].values) == [str(i) for i in truth["impact"].values]
    assert red.attrs["swing_exposure_s"] == pytest.approx(50e-6)  # the tip's fit kept clear of the contact by it
    for name in ("v_bat", "v_ball", "theta", "omega"):
        got, err, true = red[name].values, red[f"{name}_err"].values, truth[f"truth_{name}"].values
        assert np.all(np.abs(got - true) < 4 * err), (name, got, true, err)
    again = snakemake(wd, "-c2", "-n", "--", "results/filmed/reduce.nc", sheet, quality)
    assert "Nothing to be done" in again.stdout + again.stderr


def _same_as_one_job(wd, res) -> None:
    """The gathered imported_tracks.nc and imported_quality.nc equal, variable for variable, what tracking every
    clip in one process gives (the import before batches: ballbat.video.importer.ClipImport).
    """
    import xarray as xr

    from ballbat.config_checks import load_config
    from ballbat.properties import load_balls, load_bats
    from ballbat.stages.quality import quality_dataset
    from ballbat.stages.render import tracks_dataset
    from ballbat.tracks.data import clips_block
    from ballbat.tracks.formats.layout import import_block
    from ballbat.video.importer import ClipImport

    cfg = load_config(wd / "config" / "config.yaml")  # with the schema's defaults, as the workflow reads it
    block = clips_block(cfg["datasets"]["filmed"]["render"], str(res / "clips"))
    clips = ClipImport()
    tables = (load_balls(wd / "config" / "balls.csv"), load_bats(wd / "config" / "bats.csv"))
    tracks, _ = import_block(block, "datasets.filmed.render", *tables, clip_reader=clips)
    for name, one in (
        ("imported_tracks.nc", tracks_dataset(tracks)),
        ("imported_quality.nc", quality_dataset(clips.quality())),
    ):
        gathered = xr.open_dataset(res / name)
        assert sorted(gathered.variables) == sorted(one.variables), name
        for v in one.variables:
            a, b = gathered[v].values, one[v].values
            if a.dtype.kind in "OUS":
                a, b = a.astype(str), b.astype(str)
            assert a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), (name, v)
