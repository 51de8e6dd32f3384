"""Exported tables (ballbat.tracks.formats.tables): Tracker and Kinovea tables into pixels, their units and
cells checked (docs/tracks.md).
"""

from __future__ import annotations

import helpers
import numpy as np
import pytest
from helpers import same_tracks as _same
from track_files import (
    kinovea_csv_text,
    tracker_table_text,
)

from ballbat.tracks.formats import FormatError
from ballbat.tracks.formats.tables import read_kinovea_table, read_tracker_table

rows = helpers.rows  # a fixture of tests/helpers.py

TABLE_UNITS = {"time": "ms", "length": "cm", "y": "up"}


def test_exported_tables_become_pixels(tmp_path, rows):
    """World units, y up, time in s or ms: back to the pixels (y down) at the stated scale and frame rate."""
    tracks = rows[("W05", "swing")]
    k = tmp_path / "W05_swing.csv"
    k.write_text(kinovea_csv_text(tracks, 3000.0, 0.00074))
    _same(read_kinovea_table(k, TABLE_UNITS, 3000.0, 0.00074).tracks, tracks, tol=1e-3)
    t = tmp_path / "W05_swing.txt"
    t.write_text(tracker_table_text(tracks, 3000.0, 0.00074))
    got = read_tracker_table(t, {"time": "s", "length": "m", "y": "up"}, 3000.0, 0.00074).tracks
    _same(got, tracks, tol=1e-3)
    # y stated the wrong way round: the motion comes out mirrored (not silently the same)
    flipped = read_tracker_table(t, {"time": "s", "length": "m", "y": "down"}, 3000.0, 0.00074).tracks
    dy = flipped["ball"][2] - flipped["ball"][2][0]
    np.testing.assert_allclose(dy, -(tracks["ball"][2] - tracks["ball"][2][0]), atol=1e-3)


def test_tracker_table_with_a_decimal_comma(tmp_path, rows):
    """A European locale: semicolons and decimal commas, as Tracker writes them there."""
    tracks = rows[("W06", "spin")]
    text = tracker_table_text(tracks, 1000.0, 0.00125, delim=";").replace(".", ",")
    t = tmp_path / "W06_spin.txt"
    t.write_text(text)
    got = read_tracker_table(t, {"time": "s", "length": "m", "y": "up"}, 1000.0, 0.00125).tracks
    _same(got, tracks, tol=1e-3)


def test_table_at_the_wrong_frame_rate_names_rows(tmp_path, rows):
    """The frame rate off by 2x (too low): times fall between frames and the rows are named."""
    k = tmp_path / "W05_swing.csv"
    k.write_text(kinovea_csv_text(rows[("W05", "swing")], 3000.0, 0.00074))
    with pytest.raises(FormatError) as exc:
        read_kinovea_table(k, TABLE_UNITS, 1500.0, 0.00074)
    msg = "\n".join(exc.value.problems)
    assert f"{k}: line 3, track 'tip': time Time is 0.500 frames, not a whole frame" in msg
    assert "times are not whole frames at 1500 fps (units.time 'ms'): is the frame rate or the time unit wrong?" in msg


def test_exported_tables_name_cells_that_are_not_finite_numbers(tmp_path, rows):
    """Both exported tables name the line and track of a cell that is not a finite number."""
    k = tmp_path / "W05_swing.csv"
    lines = kinovea_csv_text(rows[("W05", "swing")], 3000.0, 0.00074).splitlines()
    cells = lines[2].split(",")
    cells[1], cells[2] = "inf", "abc"
    lines[2] = ",".join(cells)
    lines[3] = ",".join([lines[3].split(",")[0], "nan", "1.0", *lines[3].split(",")[3:]])
    k.write_text("\n".join(lines) + "\n")
    with pytest.raises(FormatError) as exc:
        read_kinovea_table(k, TABLE_UNITS, 3000.0, 0.00074)
    msg = "\n".join(exc.value.problems)
    assert f"{k}: line 3, track " in msg and "X 'inf', Y 'abc' are not numbers" in msg
    assert f"{k}: line 4, track " in msg and "X 'nan', Y '1.0' are not finite" in msg
    t = tmp_path / "W05_swing.txt"
    text = tracker_table_text(rows[("W05", "swing")], 3000.0, 0.00074).splitlines()
    first = next(i for i, ln in enumerate(text) if ln[:1].isdigit() or ln[:1] == "-")
    t.write_text("\n".join([*text[:first], "abc" + text[first][text[first].index("\t") :], *text[first + 1 :]]))
    with pytest.raises(FormatError, match=rf"line {first + 1}, column t: 'abc' is not a number"):
        read_tracker_table(t, {"time": "s", "length": "m", "y": "up"}, 3000.0, 0.00074)
