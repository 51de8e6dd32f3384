"""A folder of clips as a dataset's tracking files (ballbat.video.importer; docs/video.md, "In the workflow").

Slow: each import tracks its clips (1024 x 512 px) again.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
from video_clips import LAB_CAMERAS, render_clip_folder

from ballbat.properties import InputError, load_balls, load_bats
from ballbat.tracks.formats.layout import import_block
from ballbat.video.importer import ClipImport, clip_reader

ROOT = Path(__file__).parents[2]


@pytest.fixture(scope="module")
def one_impact(tmp_path_factory):
    """The first impact's two clips alone (the tests of settings the clips contradict)."""
    folder = tmp_path_factory.mktemp("one")
    return folder, render_clip_folder(folder, n=1)


def _block(folder: Path, **cameras) -> dict:
    cams = copy.deepcopy({c: {"m_per_px": v["m_per_px"]} for c, v in LAB_CAMERAS.items()})
    for cam, values in cameras.items():
        cams[cam].update(values)
    return {
        "dir": str(folder),
        "format": "video",
        "pattern": "{impact_id}_{camera}.{ext}",
        "impacts": str(folder / "impacts.csv"),
        "cameras": cams,
        "video": {"dot_radius_mm": 4.0, "marker_radius_mm": 6.0},
    }


def _tables():
    return load_balls(ROOT / "config" / "balls.csv"), load_bats(ROOT / "config" / "bats.csv")


@pytest.fixture(scope="module")
def lab_import(lab_clips):
    """The lab's folder of clips imported once (as rule import_clips does): tracks, what was read, the reader."""
    clips = ClipImport()
    tracks, imported = import_block(_block(lab_clips[0]), "datasets.vid.tracks", *_tables(), clip_reader=clips)
    return tracks, imported, clips


@pytest.mark.slow
def test_clips_are_tracked_into_the_tracks_the_reduction_reads(lab_clips, lab_import):
    true = lab_clips[1]
    tracks, imported, _ = lab_import
    assert list(tracks.impact_id) == ["W1", "W2", "W3"] and imported.settings_yaml()["files"] == 6
    # the frame rates from the clips (the config gives none)
    assert imported.cameras["swing"]["fps"] == 3000.0 and "file(s)" in imported.cameras["swing"]["fps_from"]
    # and the exposure (the tip's fit keeps clear of the contact by it)
    assert imported.cameras["swing"]["exposure_us"] == pytest.approx(50.0)
    assert "file(s)" in imported.cameras["swing"]["exposure_us_from"]
    for c in true:
        i = list(tracks.impact_id).index(c.impact_id)
        for p in c.x:
            # the dots' names are the tracker's (which is a and which b is fixed once per clip)
            names = ("dot_a", "dot_b") if p.startswith("dot") else (p,)
            n, err = min((_rms(tracks.cameras[c.camera], i, p, c, q) for q in names), key=lambda r: r[1])
            assert n > 3 and err < 0.5, (c.impact_id, c.camera, p, n, err)


@pytest.mark.slow
def test_the_trackers_quality_of_every_point_is_kept_and_written_with_units_and_provenance(
    lab_clips, lab_import, tmp_path
):
    """imported_quality.nc: every point found (as in the tracks) with its quality, every point left out with why."""
    from ballbat.pipeline.ncio import read_dataset, write_dataset
    from ballbat.stages.quality import QUALITY_TABLE, quality_columns, quality_dataset
    from ballbat.tracks.data import to_long

    tracks, _, clips = lab_import
    q = clips.quality()
    found = q["left_out"] == ""
    # the points found are the tracks' rows, point for point
    long = to_long(tracks)
    assert _rows(q, found) == _rows(long, np.isfinite(long["x_px"]))
    ball = found & (q["point"] == "ball")
    assert np.all((q["residual_px"][ball] > 0) & (q["residual_px"][ball] < 0.5))  # the edge's RMS residual, px
    assert np.all(np.isnan(q["residual_px"][found & (q["point"] != "ball")]))  # centroids: no residual
    assert np.all(q["contrast"][found] > 0) and np.all(np.isnan(q["contrast"][~found]))
    assert (~found).sum() > 0 and np.all(np.isnan(q["x_px"][~found]))  # left out: no position, a reason
    # every frame of every clip has its ball, found or left out
    assert {(i, c) for i, c in zip(q["impact_id"], q["camera"], strict=True)} == {
        (f"W{k}", c) for k in (1, 2, 3) for c in ("swing", "spin")
    }
    inputs = {"files": sorted(str(p) for p in lab_clips[0].glob("*.tif"))}
    path = write_dataset(
        quality_dataset(q),
        tmp_path / "imported_quality.nc",
        title="quality",
        rule="import_clips",
        inputs=inputs,
        config={"settings": {"format": "video"}},
    )
    ds = read_dataset(path, require=tuple(QUALITY_TABLE))
    assert ds.attrs["provenance_rule"] == "import_clips" and '"format": "video"' in ds.attrs["provenance_config"]
    assert ds.attrs["n_clips"] == 6 and ds.attrs["n_found"] == int(found.sum())
    for name in ("frame", "x_px", "y_px", "residual_px", "contrast"):
        assert ds[name].attrs["units"] == "1" and ds[name].attrs["long_name"], name
    back = quality_columns(ds)
    assert list(back["left_out"]) == list(q["left_out"])
    np.testing.assert_array_equal(back["residual_px"], q["residual_px"])


def _rows(cols: dict, sel: np.ndarray) -> list[tuple]:
    """The rows ``sel`` of long columns as sorted (impact, camera, point, frame, x to 1e-6 px)."""
    names = ("impact_id", "camera", "point")
    text = [cols[k][sel].astype(str) for k in names]
    return sorted(zip(*text, cols["frame"][sel].astype(int), np.round(cols["x_px"][sel].astype(float), 6), strict=True))


def _rms(ct, i: int, p: str, c, q: str) -> tuple[int, float]:
    """Points of ``p`` tracked in impact ``i`` and their RMS distance from the truth's ``q`` (px)."""
    at = {int(f): k for k, f in enumerate(c.frames)}
    have = [(j, at[int(f)]) for j, f in enumerate(ct.frames()[i]) if np.isfinite(ct.x[p][i][j]) and int(f) in at]
    d = [np.hypot(ct.x[p][i][j] - c.x[q][k], ct.y[p][i][j] - c.y[q][k]) for j, k in have]
    return len(d), float(np.sqrt(np.nanmean(np.square(d))))


@pytest.mark.slow
def test_a_scale_the_clips_contradict_is_named(one_impact):
    folder, _ = one_impact
    wrong = _block(folder, spin={"m_per_px": 0.00125 * 1.12})  # typed 12 % large: the ball 11 % small
    with pytest.raises(InputError, match=r"W1_spin\.tif: the ball measures .* the clip says m_per_px 0\.001"):
        import_block(wrong, "datasets.vid.tracks", *_tables(), clip_reader=clip_reader)


@pytest.mark.slow
def test_a_frame_rate_the_clips_contradict_is_named(one_impact):
    folder, _ = one_impact
    wrong = _block(folder, swing={"fps": 2000})
    with pytest.raises(InputError, match=r"cameras\.swing\.fps: the config says 2000 but .*W1_swing\.tif says 3000"):
        import_block(wrong, "datasets.vid.tracks", *_tables(), clip_reader=clip_reader)


@pytest.mark.slow
def test_an_exposure_the_clips_contradict_is_named(one_impact):
    """The config's exposure against the clip's (its 0, the default, is "not known": the clip's is taken)."""
    folder, _ = one_impact
    wrong = _block(folder, swing={"exposure_us": 500})  # 1/2000 s typed for 1/20000 s
    with pytest.raises(
        InputError, match=r"cameras\.swing\.exposure_us: the config says 500 us but .*W1_swing\.tif says 50 us"
    ):
        import_block(wrong, "datasets.vid.tracks", *_tables(), clip_reader=clip_reader)
    _, imported = import_block(_block(folder, swing={"exposure_us": 0.0}), "x", *_tables(), clip_reader=clip_reader)
    assert imported.cameras["swing"]["exposure_us"] == pytest.approx(50.0)


@pytest.mark.slow
def test_a_video_folder_needs_the_scale(one_impact):
    folder, _ = one_impact
    block = _block(folder)
    del block["cameras"]["spin"]["m_per_px"]
    with pytest.raises(InputError, match=r"cameras\.spin\.m_per_px: missing \(a clip holds no scale"):
        import_block(block, "datasets.vid.tracks", *_tables(), clip_reader=clip_reader)


def test_markers_given_for_a_folder_of_tool_files_are_named(tmp_path):
    (tmp_path / "impacts.csv").write_text("impact_id,bat,ball\nW1,wood,baseball\n")
    block = {**_block(tmp_path), "format": "tracker", "points": {p: p for p in ("ball", "bat_tip", "dot_a", "dot_b")}}
    with pytest.raises(InputError, match=r"datasets\.vid\.tracks\.video: given, but only a folder of clips"):
        import_block(block, "datasets.vid.tracks", *_tables(), clip_reader=clip_reader)


@pytest.mark.slow
def test_clips_tracked_side_by_side_give_the_same_tracks(one_impact):
    """ClipReader in two processes (the import job's threads) gives one clip at a time's tracks, in order."""
    from functools import partial

    folder, _ = one_impact
    got = [
        import_block(_block(folder), "datasets.vid.tracks", *_tables(), clip_reader=partial(clip_reader, workers=w))[0]
        for w in (1, 2)
    ]
    for cam in ("swing", "spin"):
        one, two = got[0].cameras[cam], got[1].cameras[cam]
        np.testing.assert_array_equal(one.frame0, two.frame0)
        for p in one.x:
            np.testing.assert_array_equal(one.x[p], two.x[p])
            np.testing.assert_array_equal(one.y[p], two.y[p])
