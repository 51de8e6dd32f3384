"""Reading the tracking tools' own files (docs/tracks.md, "Files of tracking tools").

The files are written by tests/track_files.py, shaped as Tracker and Kinovea write them, from
the tracks of config/examples/tracked_tracks.csv (rendered by ballbat's renderer).
"""

from __future__ import annotations

from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from track_files import (
    kva_text,
    read_long_csv,
)

from ballbat.tracks.formats import FormatError
from ballbat.tracks.formats.kinovea import read_kva

ROOT = Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "config" / "examples"


@pytest.fixture(scope="module")
def rows():
    return read_long_csv(EXAMPLE / "tracked_tracks.csv")


def _same(got, want, tol=0.0):
    assert set(got) == set(want)
    for name, (f, x, y) in want.items():
        gf, gx, gy = got[name]
        np.testing.assert_array_equal(gf - gf.min(), f - f.min())
        np.testing.assert_allclose(gx - gx[0], x - x[0], atol=tol, rtol=0)
        np.testing.assert_allclose(gy - gy[0], y - y[0], atol=tol, rtol=0)


def test_kva_timestamps_calibration(tmp_path, rows):
    """Kinovea: frame = (t - FirstTimeStamp) / AverageTimeStampsPerFrame; fps = CaptureFramerate; scale: a line."""
    tracks = rows[("W04", "spin")]
    p = tmp_path / "W04_spin.kva"
    p.write_text(kva_text(tracks, 1000.0, 0.00125, per_frame=1001, first=123456, video_fps=29.97))
    ft = read_kva(p)
    _same(ft.tracks, tracks)
    assert ft.fps == 1000.0
    assert ft.m_per_px == pytest.approx(0.00125, rel=1e-6)
    p.write_text(kva_text(tracks, 1000.0, None, mirror=True))
    with pytest.raises(FormatError, match="Mirror is true"):
        read_kva(p)
    root = ET.fromstring(kva_text(tracks, 1000.0, None))
    point = root.findall("Tracks/Track")[0].findall("TrackPointList/TrackPoint")[1]
    x, y, t, r = point.text.split(";")
    point.text = f"{x};{y};{int(t) + 200};{r}"  # a point between two frames
    p.write_bytes(ET.tostring(root))
    with pytest.raises(
        FormatError, match=rf"track 'ball', point 2 \(t = {int(t) + 200}\): its timestamp is [0-9]+\.391 "
    ):
        read_kva(p)
