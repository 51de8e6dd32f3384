"""The column reader of a plain tracks CSV agrees with the row-by-row reader (issue 34: a 10^6-row file)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ballbat.properties import InputError
from ballbat.tracks import io as tio

EXAMPLE = Path(__file__).resolve().parents[2] / "config" / "examples"


def _same(a, b) -> None:
    assert a.impact_id.tolist() == b.impact_id.tolist()
    for cam in a.cameras:
        ca, cb = a.cameras[cam], b.cameras[cam]
        np.testing.assert_array_equal(ca.frame0, cb.frame0)
        for p in ca.x:
            np.testing.assert_array_equal(ca.x[p], cb.x[p])
            np.testing.assert_array_equal(ca.y[p], cb.y[p])


def test_columns_and_rows_give_the_same_tracks(tmp_path, monkeypatch):
    """The shipped tracked example read by columns, and by rows (the column reader switched off)."""
    tracks, impacts = EXAMPLE / "tracked_tracks.csv", EXAMPLE / "tracked_impacts.csv"
    assert tio._fast_csv(tracks, {"W01": "row 2"}) is None  # impacts the file does not match: rows decide
    by_columns = tio.load_tracks(tracks, impacts)
    monkeypatch.setattr(tio, "_fast_csv", lambda *a: None)
    _same(by_columns, tio.load_tracks(tracks, impacts))


@pytest.mark.parametrize(
    "edit",
    [
        lambda t: t.replace("W03,swing,ball,", "W03, swing,ball,", 1),  # a space: rows read it
        lambda t: t.replace(",", ";").replace(".", ","),  # European Excel
    ],
)
def test_files_the_column_reader_declines_are_read_by_rows(tmp_path, edit):
    """A space after a comma or a semicolon file falls back to the row reader, with the same result."""
    tracks, impacts = EXAMPLE / "tracked_tracks.csv", EXAMPLE / "tracked_impacts.csv"
    path = tmp_path / "tracks.csv"
    path.write_text(edit(tracks.read_text()))
    ids = {row: row for row in ("W01",)}
    assert tio._fast_csv(path, ids) is None
    _same(tio.load_tracks(tracks, impacts), tio.load_tracks(path, impacts))


def test_a_frame_twice_is_named_by_the_row_checks(tmp_path):
    """The column reader does not resolve a duplicated frame: the row checks name both rows."""
    tracks, impacts = EXAMPLE / "tracked_tracks.csv", EXAMPLE / "tracked_impacts.csv"
    lines = tracks.read_text().splitlines()
    dup = next(k for k, ln in enumerate(lines) if ln.startswith("W03,swing,ball,"))
    path = tmp_path / "tracks.csv"
    path.write_text("\n".join([*lines, lines[dup]]) + "\n")
    with pytest.raises(InputError) as err:
        tio.load_tracks(path, impacts)
    assert f"row {len(lines) + 1}, column frame" in err.value.problems[0] and "appears twice" in err.value.problems[0]


@pytest.fixture(scope="module")
def long_file(tmp_path_factory):
    from helpers import one_long_track

    path = tmp_path_factory.mktemp("long") / "tracks.nc"
    one_long_track(path, factor=5)
    return path


def test_a_long_track_is_held_in_a_block_of_its_own(long_file, monkeypatch):
    """30 impacts, one track 5x longer, a lowered block budget: blocks hold the same tracks, the long one apart."""
    from helpers import BALLS, BATS

    from ballbat.tracks import data

    one = tio.load_tracks(long_file, balls=BALLS, bats=BATS)
    assert isinstance(one, data.Tracks) and one.cameras["swing"].n_columns == 330  # impact 4's 5 x 66 frames
    monkeypatch.setattr(data, "BLOCK_BYTES", 100_000)  # 30 impacts x 330 columns would take 0.8 MB
    blocks = tio.load_tracks(long_file, balls=BALLS, bats=BATS)
    assert isinstance(blocks, data.TrackBlocks) and len(blocks.blocks) > 1
    assert [idx.tolist() for idx in blocks.index if 4 in idx] == [[4]]  # impact 4 alone
    assert all(b.cameras["swing"].n_columns < 100 for b in blocks.blocks if b.n > 1)
    assert blocks.impact_id.tolist() == one.impact_id.tolist() and blocks.ball.tolist() == one.ball.tolist()
    for k, v in one.truth.items():
        np.testing.assert_array_equal(blocks.truth[k], v)
    for cam, ct in one.cameras.items():
        np.testing.assert_array_equal(blocks.frame0(cam), ct.frame0)
        for i in range(one.n):
            blk, j = blocks.locate(i)
            for p in ct.x:
                w = blk.cameras[cam].n_columns
                np.testing.assert_array_equal(blk.cameras[cam].x[p][j], ct.x[p][i, :w])
                np.testing.assert_array_equal(blk.cameras[cam].y[p][j], ct.y[p][i, :w])
                assert np.isnan(ct.x[p][i, w:]).all()  # nothing beyond the block's own width


def test_a_track_too_long_is_named(long_file, monkeypatch):
    """Past MAX_TRACK_FRAMES (lowered here) a track is refused naming the file, impact, camera and frames."""
    from helpers import BALLS, BATS

    from ballbat.tracks import data

    monkeypatch.setattr(data, "MAX_TRACK_FRAMES", 300)
    with pytest.raises(InputError) as err:
        tio.load_tracks(long_file, balls=BALLS, bats=BATS)
    (line,) = err.value.problems
    assert line.startswith(f"{long_file}: impact '4' spans 330 frames in the swing camera (")
    assert "more than the 300 one impact's track may span" in line


def test_tracks_too_large_even_in_blocks_are_named(long_file, monkeypatch):
    """Past MAX_DENSE_BYTES (lowered here) of a camera's tracks in their blocks, the dataset is refused by name."""
    from helpers import BALLS, BATS

    from ballbat.tracks import data

    monkeypatch.setattr(data, "BLOCK_BYTES", 100_000)
    # the swing camera's blocks: (25 x 73 + 330 + 4 x 82 columns) x 2 points x 16 bytes = 79 456 bytes
    monkeypatch.setattr(data, "MAX_DENSE_BYTES", 50_000)
    with pytest.raises(InputError) as err:
        tio.load_tracks(long_file, balls=BALLS, bats=BATS)
    (line,) = err.value.problems
    assert line.startswith(f"{long_file}: the swing camera's tracks of 30 impacts would take 7.4e-05 GiB (in 3 block")
    assert line.endswith(f"more than {50_000 / 2**30:g} GiB: track fewer frames per impact, or split the dataset")
