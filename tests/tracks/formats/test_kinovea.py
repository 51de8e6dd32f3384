"""Kinovea files (ballbat.tracks.formats.kinovea): timestamps and calibration (docs/tracks.md)."""

from __future__ import annotations

from xml.etree import ElementTree as ET

import helpers
import pytest
from helpers import same_tracks as _same
from track_files import (
    kva_text,
)

from ballbat.tracks.formats import FormatError
from ballbat.tracks.formats.kinovea import read_kva

rows = helpers.rows  # a fixture of tests/helpers.py


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
    between = rf"track 'ball', point 2 \(t = {int(t) + 200}\): its timestamp is [0-9]+\.391 "
    with pytest.raises(FormatError, match=between):
        read_kva(p)
