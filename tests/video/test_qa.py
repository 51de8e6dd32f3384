"""The contact sheet's frames (ballbat.video.qa) and its figure (ballbat.plotting_tracks.contact_sheet)."""

from __future__ import annotations

import numpy as np
import pytest
from video_clips import LAB_CAMERAS

from ballbat.plotting_tracks import contact_sheet
from ballbat.tracks.formats.layout import import_block
from ballbat.video.importer import clip_reader
from ballbat.video.qa import block_clips, sheet_rows


@pytest.mark.slow
def test_the_sheet_shows_each_clips_frames_with_the_points_tracked_in_them(lab_clips, balls, bats):
    folder, true = lab_clips
    block = {
        "dir": str(folder),
        "format": "video",
        "pattern": "{impact_id}_{camera}.{ext}",
        "impacts": str(folder / "impacts.csv"),
        "cameras": {c: {"m_per_px": v["m_per_px"]} for c, v in LAB_CAMERAS.items()},
        "video": {"dot_radius_mm": 4.0, "marker_radius_mm": 6.0},
    }
    tracks, _ = import_block(block, "datasets.vid.tracks", balls, bats, clip_reader=clip_reader)
    rows = sheet_rows(block_clips(block), tracks, [0, 2], n=4)
    assert [r.label for r in rows] == ["W1 swing", "W1 spin", "W3 swing", "W3 spin"]
    truth = {(c.impact_id, c.camera): c for c in true}
    for row in rows:
        c = truth[tuple(row.label.split())]
        assert len(row.frames) == 4 and len({f for f, _, _ in row.frames}) == 4
        assert sum("ball" in points for _, _, points in row.frames) >= 2  # the frames spread over the tracking
        for frame, img, points in row.frames:
            assert img.shape == (c.height, c.width) and points  # each frame shown has a point tracked
            k = list(c.frames).index(frame)
            for p, (x, y) in points.items():
                names = ("dot_a", "dot_b") if p.startswith("dot") else (p,)  # dots: the tracker's names may be swapped
                near = min(np.hypot(x - c.x[t][k], y - c.y[t][k]) for t in names)
                assert near < 1.0, (row.label, frame, p)
    fig = contact_sheet(rows)
    assert len([ax for ax in fig.axes if ax.images]) == 16
