"""Stage render_clips (ballbat.stages.clips; docs/video.md, "A filmed synthetic experiment")."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from ballbat.pipeline.config import checked_block
from ballbat.stages import clips, render, simulate
from ballbat.video.io import open_clip

RENDER = {
    "cameras": {
        "swing": {"fps": 3000, "m_per_px": 0.00074, "tee_px": [300, 200], "width_px": 512, "height_px": 320},
        "spin": {"fps": 1000, "m_per_px": 0.00125, "tee_px": [200, 180], "width_px": 400, "height_px": 320},
    },
    "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
    "seed": 4,
    "video": {"format": "tif"},
}


def test_every_video_setting_arrives_in_the_clips_look():
    """The block's defaults filled (schema), then each setting changed on its own reaches the Look."""
    video = checked_block(copy.deepcopy(RENDER), "render")["video"]
    base = clips.clip_look(video, 1)
    assert (base.exposure_s, base.bit_depth) == (pytest.approx(video["exposure_us"] * 1e-6), video["bit_depth"])
    changes = {"exposure_us": 120.0, "bit_depth": 12, "dot_radius_mm": 5.5, "marker_radius_mm": 9.0}
    field = {"exposure_us": "exposure_s", "bit_depth": "bit_depth", "dot_radius_mm": "dot_radius_m"}
    field["marker_radius_mm"] = "marker_radius_m"
    for key, value in changes.items():
        look = clips.clip_look({**video, key: value}, 1)
        scale = {"exposure_us": 1e-6, "dot_radius_mm": 1e-3, "marker_radius_mm": 1e-3}.get(key, 1)
        assert getattr(look, field[key]) == pytest.approx(value * scale) != getattr(base, field[key])


@pytest.fixture(scope="module")
def experiment(config, balls, bats):
    """Two simulated impacts (the default dataset's settings, two baseballs on wood)."""
    ds = copy.deepcopy(config["datasets"]["synthetic"]["synthetic"])
    ds["impacts"] = {"baseball": {"wood": 2}}
    ds["e_x"] = {"baseball": {"wood": 0.464}}
    return simulate.run(simulate.from_params(ds), balls, bats)


@pytest.mark.parametrize(("fmt", "crf"), [("mkv", 18), ("mp4", 30)])  # TIFF: tests/workflow/test_video.py
def test_clips_are_written_whole_in_the_format_asked(tmp_path, experiment, balls, fmt, crf):
    block = checked_block({**copy.deepcopy(RENDER), "video": {"format": fmt, "crf": crf}}, "render")
    out = tmp_path / "clips"
    written, n_frames = clips.render_clips(render.from_params(block), block["video"], experiment, balls, out)
    ids = [str(i) for i in experiment["impact"].values]
    assert sorted(p.name for p in written) == sorted(f"{i}_{c}.{fmt}" for i in ids for c in ("swing", "spin"))
    assert (out / "impacts.csv").read_text().splitlines() == [
        "impact_id,bat,ball",
        *(f"{i},wood,baseball" for i in ids),
    ]
    assert [p.name for p in tmp_path.iterdir()] == ["clips"]  # no temporary folder left
    assert n_frames == sum(open_clip(p).info.n_frames for p in written)
    info = open_clip(out / f"{ids[0]}_swing.{fmt}").info
    assert info.fps == 3000.0 and (info.width, info.height) == (512, 320)
    frame = next(open_clip(out / f"{ids[0]}_spin.{fmt}").frames())[2]
    assert frame.shape == (320, 400) and frame.dtype == np.uint8 and frame.std() > 1


def test_a_failed_drawing_leaves_nothing_and_keeps_what_was_there(tmp_path, experiment, balls, monkeypatch):
    block = checked_block(copy.deepcopy(RENDER), "render")
    out = tmp_path / "clips"
    out.mkdir()
    (out / "earlier.tif").write_bytes(b"the earlier run's")

    def broken(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr("ballbat.video.io.write_clip", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        clips.render_clips(render.from_params(block), block["video"], experiment, balls, out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clips"]
    assert (out / "earlier.tif").read_bytes() == b"the earlier run's"
