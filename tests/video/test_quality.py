"""The tracker's quality per camera (ballbat.video.qa.camera_quality), its file (ballbat.stages.quality) and its
figure (ballbat.plotting_tracks.quality_figure); docs/video.md, "In the workflow".
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from ballbat.pipeline.checked import DamagedFileError
from ballbat.pipeline.ncio import MetadataError, read_dataset, write_dataset
from ballbat.plotting_tracks import quality_figure, save_figure
from ballbat.stages.quality import QUALITY_TABLE, quality_columns, quality_dataset
from ballbat.video.qa import camera_quality, reason_kind
from ballbat.video.track import Found, found_columns
from workflow_helpers import assert_not_blank


def _clip(impact_id: str, camera: str, n: int, seed: int) -> dict:
    """A quality table of one clip of ``n`` frames, as the tracker lays it out (found_columns of a Found)."""
    rng = np.random.default_rng(seed)
    found = Found()
    points = ("ball", "bat_tip") if camera == "swing" else ("ball", "dot_a", "dot_b")
    for k in range(100, 100 + n):
        if k % 5 == 0:
            found.leave_out("ball", k, f"ball edge not round (residual {0.5 + rng.random():.2f} px; occluded)")
            for p in points[1:]:
                found.leave_out(p, k, "no ball" if p != "bat_tip" else "no tip marker found")
            continue
        found.add("ball", k, 300 + k, 200.0, 0.05 + 0.1 * rng.random(), 150 + 10 * rng.random())
        for p in points[1:]:
            if p == "dot_b" and k % 3 == 0:
                found.leave_out(p, k, "not seen inside the ball (hidden or on the limb)")
                found.leave_out("dot", k, f"spot at {300 + k:.1f}, 190.0 on the limb (0.9{k % 10} of the radius)")
            else:
                found.add(p, k, 300 + k, 190.0, np.nan, 60 + 20 * rng.random())
    return found_columns(found, impact_id, camera)[1]


@pytest.fixture(scope="module")
def table() -> dict:
    """Three impacts' clips in both cameras, 12-20 frames each, every kind of row."""
    tables = [
        _clip(f"W{i}", cam, 12 + 4 * i, seed=10 * i + (cam == "spin")) for i in range(3) for cam in ("swing", "spin")
    ]
    return {k: np.concatenate([t[k] for t in tables]) for k in tables[0]}


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


def test_the_quality_file_holds_the_table_with_units_and_provenance(table, tmp_path):
    path = write_dataset(
        quality_dataset(table), tmp_path / "imported_quality.nc", title="t", rule="import_clips", inputs={}, config={}
    )
    ds = read_dataset(path, require=tuple(QUALITY_TABLE))
    assert ds.attrs["provenance_rule"] == "import_clips" and ds.attrs["n_clips"] == 6
    assert ds.attrs["n_found"] + ds.attrs["n_left_out"] == ds.attrs["n_rows"] == table["frame"].size
    assert ds["residual_px"].attrs["units"] == "1" and "pixels" in ds["residual_px"].attrs["long_name"]
    back = quality_columns(ds)
    for k in QUALITY_TABLE:
        if back[k].dtype.kind == "f":
            np.testing.assert_array_equal(back[k], table[k])
        else:
            assert list(back[k]) == list(table[k]), k


def test_a_file_that_is_not_a_quality_table_is_named(tmp_path):
    ds = quality_dataset(_clip("W1", "spin", 3, 0)).drop_vars("contrast")
    path = write_dataset(ds, tmp_path / "q.nc", title="t", rule="r", inputs={}, config={})
    with pytest.raises(MetadataError, match=r"q\.nc: missing variable\(s\) contrast"):
        read_dataset(path, require=tuple(QUALITY_TABLE))
    path.write_bytes(path.read_bytes()[:100])
    with pytest.raises(DamagedFileError, match=r"q\.nc"):
        read_dataset(path, require=tuple(QUALITY_TABLE))
