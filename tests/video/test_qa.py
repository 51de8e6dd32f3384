"""What the clips' QA figures show (ballbat.video.qa) and the figures (ballbat.plotting_tracks).

The contact sheet's frames (``sheet_rows``, ``contact_sheet``); the tracker's quality per camera
(``camera_quality``, ``quality_figure``; docs/video.md, "In the workflow").
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from video_clips import LAB_CAMERAS, quality_table

from ballbat.plotting_tracks import contact_sheet, quality_figure, save_figure
from ballbat.tracks.formats.layout import import_block
from ballbat.video.importer import clip_reader
from ballbat.video.qa import block_clips, camera_quality, reason_kind, sheet_rows
from workflow_helpers import assert_not_blank


@pytest.fixture(scope="module")
def table() -> dict:
    """A small quality table: three impacts' clips in both cameras (video_clips.quality_table)."""
    return quality_table()


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


def test_reasons_are_counted_by_kind():
    assert reason_kind("ball edge not round (residual 0.61 px; occluded or on clutter)") == "ball edge not round"
    assert reason_kind("2 balls found") == "n balls found"
    assert reason_kind("ball edge seen on 12 of 48 rays (occluded, blurred or on clutter)") == (
        "ball edge seen on n of n rays"
    )
    assert reason_kind("no tip marker found") == "no tip marker found"
    assert reason_kind("spot at 312.4, 190.0 on the limb (0.93 of the radius)") == "spot on the limb"
    assert reason_kind("a spot at 5.0, -3.5 too faint for the marker (20 vs 80)") == "a spot too faint for the marker"


def test_each_cameras_quality_is_the_tables(table):
    cams = camera_quality(table)
    assert [q.camera for q in cams] == ["swing", "spin"]
    for q in cams:
        sel = table["camera"] == q.camera
        why, point = table["left_out"][sel], table["point"][sel]
        assert q.clips == 3 and q.frames == 12 + 16 + 20
        assert q.found == int((why == "").sum()) and q.found + q.left_out == int(sel.sum())
        ball = sel & (table["point"] == "ball") & (table["left_out"] == "")
        np.testing.assert_array_equal(np.sort(q.residual_px), np.sort(table["residual_px"][ball]))
        assert q.counts[("ball", "found")] == int(ball.sum())
        assert q.counts[("ball", "ball edge not round")] == int(((point == "ball") & (why != "")).sum())
    spin = cams[1]
    dots = (table["camera"] == "spin") & np.isin(table["point"], ["dot_a", "dot_b"]) & (table["left_out"] == "")
    assert set(spin.contrast) == {"ball", "dots"} and spin.contrast["dots"].size == int(dots.sum())
    limb = int(((table["camera"] == "spin") & (table["point"] == "dot")).sum())
    assert limb > 0 and spin.counts[("dots", "spot on the limb")] == limb  # one kind, whatever the numbers


def test_the_figure_is_a_picture_and_its_bars_are_the_tables_counts(table, tmp_path):
    cams = camera_quality(table)
    fig = quality_figure(cams)
    assert "6 clips, 96 frames" in fig.get_suptitle()
    counts_axes = [ax for ax in fig.axes if ax.get_xlabel() == "points"]
    assert len(counts_axes) == 2
    for ax, cam in zip(counts_axes, ("swing", "spin"), strict=True):
        sel = table["camera"] == cam
        kinds = Counter(
            (p, "found" if w == "" else reason_kind(w))
            for p, w in zip(table["point"][sel], table["left_out"][sel], strict=True)
        )
        labels = [t.get_text() for t in ax.get_yticklabels()]
        widths = [round(b.get_width()) for b in ax.patches]
        expect = {}
        for (p, what), n in kinds.items():
            p = "dots" if p.startswith("dot") else p
            expect[f"{p}: {what}"] = expect.get(f"{p}: {what}", 0) + n
        assert dict(zip(labels, widths, strict=True)) == expect
    png = save_figure(fig, tmp_path / "q.png")
    assert_not_blank(png)
