"""Tracker projects (ballbat.tracks.formats.tracker): .trk marks, frames and settings, .trz (docs/tracks.md)."""

from __future__ import annotations

import copy
import zipfile
from xml.etree import ElementTree as ET

import helpers
import numpy as np
import pytest
from helpers import same_tracks as _same
from track_files import (
    trk_text,
    write_trz,
)

from ballbat.tracks.formats import FormatError
from ballbat.tracks.formats.tracker import read_trk, read_trz

rows = helpers.rows  # a fixture of tests/helpers.py


def test_trk_gives_the_marks_frames_and_settings(tmp_path, rows):
    """Tracker's framedata [n] is the mark at video frame n (image pixels); fps from delta_t; scale from coords."""
    tracks = rows[("W01", "swing")]
    p = tmp_path / "W01_swing.trk"
    p.write_text(trk_text(tracks, 3000.0, 0.00074, unit="cm"))
    ft = read_trk(p)
    for name, (f, x, y) in tracks.items():  # unrotated axes: the image pixels themselves, frames unchanged
        np.testing.assert_array_equal(ft.tracks[name][0], f)
        np.testing.assert_array_equal(ft.tracks[name][1], x)
        np.testing.assert_array_equal(ft.tracks[name][2], y)
    assert ft.fps == pytest.approx(3000.0, rel=1e-12)
    assert ft.m_per_px == pytest.approx(0.00074, rel=1e-12)
    assert "delta_t" in ft.source["fps"] and "px/cm" in ft.source["m_per_px"]


def test_trk_clip_with_a_step_size(tmp_path, rows):
    """Marks on every other frame of a clip with step size 2 keep their video frame numbers."""
    tracks = {n: tuple(a[::2] for a in t) for n, t in rows[("W01", "swing")].items()}
    f0 = min(t[0][0] for t in tracks.values())
    tracks = {n: t for n, t in tracks.items() if ((t[0] - f0) % 2 == 0).all()}
    assert tracks
    p = tmp_path / "W01_swing.trk"
    p.write_text(trk_text(tracks, 3000.0, 0.00074, step=2))
    ft = read_trk(p)
    for name, (f, x, _) in tracks.items():
        np.testing.assert_array_equal(ft.tracks[name][0], f)
        np.testing.assert_array_equal(ft.tracks[name][1], x)
    p.write_text(trk_text(tracks, 3000.0, 0.00074, step=2, extra_mark=int(f0) + 1))
    off_step = rf"frame {int(f0) + 1}: the mark is not on a step of the clip \(frames {int(f0)}, "
    with pytest.raises(FormatError, match=off_step):
        read_trk(p)


def test_trk_turned_axes_are_undone(tmp_path, rows):
    """A coordinate system turned by 7 deg: ballbat's x-axis is the lab's, as set in Tracker."""
    tracks = rows[("W02", "spin")]
    p = tmp_path / "a.trk"
    p.write_text(trk_text(tracks, 1000.0, 0.00125, angle_deg=7.0, origin=(512.5, 300.25)))
    ft = read_trk(p)
    _same(ft.tracks, tracks, tol=1e-9)
    assert "angle 7" in ft.source["axes"]


def test_trk_mark_off_the_clip_is_named(tmp_path, rows):
    p = tmp_path / "W01_swing.trk"
    p.write_text(trk_text(rows[("W01", "swing")], 3000.0, 0.00074, extra_mark=2))
    with pytest.raises(FormatError) as exc:
        read_trk(p)
    msg = "\n".join(exc.value.problems)
    assert f"{p}: track 'ball', frame 2: the mark is not on a step of the clip" in msg


def test_trk_changing_coordinate_system_is_refused(tmp_path, rows):
    """A key frame of the coordinate system with another scale: one fixed system per file is needed."""
    root = ET.fromstring(trk_text(rows[("W01", "swing")], 3000.0, 0.00074))
    coords = next(p for p in root.findall("property") if p.get("name") == "coords").find("object")
    frames = next(p for p in coords.findall("property") if p.get("name") == "framedata")
    key = copy.deepcopy(frames.find("property"))
    key.set("name", "[40]")
    next(p for p in key.iter("property") if p.get("name") == "xscale").text = "1400.0"
    frames.append(key)
    p = tmp_path / "W01_swing.trk"
    p.write_bytes(ET.tostring(root))
    with pytest.raises(FormatError, match=r"W01_swing.trk: the coordinate system changes at frame 40"):
        read_trk(p)


def test_trz_holds_exactly_one_project(tmp_path, rows):
    tracks = rows[("W03", "swing")]
    p = tmp_path / "W03_swing.trz"
    write_trz(p, trk_text(tracks, 3000.0, 0.00074), "W03_swing.trk")
    ft = read_trz(p)
    _same(ft.tracks, tracks)
    assert ft.path.endswith("W03_swing.trz:W03_swing.trk")
    two = tmp_path / "two.trz"
    with zipfile.ZipFile(two, "w") as z:
        z.writestr("a.trk", "<x/>")
        z.writestr("b.trk", "<x/>")
    not_one = r"two.trz: a .trz must hold exactly one .trk project \(found: a.trk, b.trk\)"
    with pytest.raises(FormatError, match=not_one):
        read_trz(two)
