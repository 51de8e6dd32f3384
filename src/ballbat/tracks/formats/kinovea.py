"""Kinovea annotation files (``.kva``, XML ``<KinoveaVideoAnalysis>``, format 2.x).

What ballbat reads:

* ``CaptureFramerate``: the camera's real frame rate (a high-speed clip plays back slower;
  Kinovea keeps the capture rate apart), the frame rate of the tracks;
* ``AverageTimeStampsPerFrame`` and ``FirstTimeStamp``: a track point's frame is
  ``(t - FirstTimeStamp) / AverageTimeStampsPerFrame``;
* ``Calibration``: a ``CalibrationLine`` (``Length`` in the ``Unit``, ``Segment`` ``A``, ``B`` in
  image pixels) gives the pixel scale; a ``CalibrationPlane`` (perspective) or the unit
  ``Pixels`` gives none (the config then states ``m_per_px``);
* ``Tracks``: each ``Track``'s ``name`` and its ``TrackPointList``: ``TrackPoint`` text
  ``x;y;t[;r]``, image pixels (y downward) at timestamp ``t``.

``Mirror`` or an image ``Rotation`` other than ``Rotate0`` is refused: ballbat cannot tell from
the file which way the stored points then face.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING
from xml.etree import ElementTree as ET

import numpy as np

from . import DUPLICATE_RULE, FileTracks, FormatError, finite_number, length_to_m, read_limited, whole_frames

if TYPE_CHECKING:
    import os

#: Kinovea's length units (enum LengthUnit) -> ballbat's names; None: no scale.
KINOVEA_UNITS = {
    "Millimeters": "mm",
    "Centimeters": "cm",
    "Meters": "m",
    "Inches": "in",
    "Feet": "ft",
    "Yards": "yd",
    "Percentage": None,
    "Pixels": None,
}


def _float(text: str | None, what: str, problems: list[str]) -> float | None:
    return finite_number(text, f"{what}:", problems)


def _point(text: str | None, what: str, problems: list[str]) -> tuple[float, float] | None:
    parts = (text or "").split(";")
    if len(parts) != 2:
        problems.append(f"{what}: {text!r} is not a point 'x;y'")
        return None
    a, b = (_float(p, what, problems) for p in parts)
    return None if a is None or b is None else (a, b)


def read_kva(path: str | os.PathLike[str]) -> FileTracks:
    """Read a Kinovea ``.kva`` file."""
    path = Path(path)
    data = read_limited(path)
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        raise FormatError([f"{path}: not a Kinovea file (XML does not parse: {exc})"]) from None
    if root.tag != "KinoveaVideoAnalysis":
        raise FormatError([f"{path}: not a Kinovea file (the root is <{root.tag}>, not <KinoveaVideoAnalysis>)"])
    problems: list[str] = []
    source: dict[str, str] = {}
    mirror = (root.findtext("Mirror") or "false").strip().lower()
    if mirror == "true":
        problems.append(f"{path}: Mirror is true (the video is shown mirrored): turn it off in Kinovea and save again")
    rotation = (root.findtext("Rotation") or "Rotate0").strip()
    if rotation not in ("Rotate0", "None", ""):
        problems.append(f"{path}: Rotation is {rotation}: ballbat reads unrotated images only")

    fps, per_frame, first = _timing(root, path, problems, source)
    m_per_px = _calibration(root, path, problems, source)
    tracks = _tracks(root, path, per_frame, first, problems)
    if problems:
        raise FormatError(problems)
    return FileTracks(path=str(path), tracks=tracks, fps=fps, m_per_px=m_per_px, source=source)


def _timing(root, path: Path, problems: list[str], source: dict) -> tuple[float | None, float | None, float]:
    """Return the capture frame rate (None: not given), the timestamps per frame and the first timestamp."""
    fps = None
    if root.find("CaptureFramerate") is not None:
        fps = _float(root.findtext("CaptureFramerate"), f"{path}: CaptureFramerate", problems)
        if fps is not None and fps <= 0:
            problems.append(f"{path}: CaptureFramerate {fps} must be positive")
            fps = None
        elif fps is not None:
            source["fps"] = f"CaptureFramerate {fps:g}"
    per_frame = None
    if root.find("AverageTimeStampsPerFrame") is None:
        problems.append(f"{path}: no AverageTimeStampsPerFrame (needed to turn timestamps into frames)")
    else:
        per_frame = _float(root.findtext("AverageTimeStampsPerFrame"), f"{path}: AverageTimeStampsPerFrame", problems)
        if per_frame is not None and per_frame <= 0:
            problems.append(f"{path}: AverageTimeStampsPerFrame {per_frame} must be positive")
            per_frame = None
    first = 0.0
    if root.find("FirstTimeStamp") is not None:
        first = _float(root.findtext("FirstTimeStamp"), f"{path}: FirstTimeStamp", problems) or 0.0
    return fps, per_frame, first


def _calibration(root, path: Path, problems: list[str], source: dict) -> float | None:
    """Return m_per_px from a calibration line (None: no calibration, a plane or pixels)."""
    m_per_px = None
    cal = root.find("Calibration")
    if cal is not None:
        unit_el = cal.find("Unit")
        kunit = (unit_el.text or "").strip() if unit_el is not None else "Pixels"
        if kunit not in KINOVEA_UNITS:
            problems.append(f"{path}: Calibration Unit {kunit!r} is unknown (known: {', '.join(KINOVEA_UNITS)})")
            kunit = "Pixels"
        line = cal.find("CalibrationLine")
        if cal.find("CalibrationPlane") is not None and KINOVEA_UNITS[kunit]:
            source["m_per_px"] = "none: a plane (perspective) calibration is not read; the config gives m_per_px"
        elif line is not None and KINOVEA_UNITS[kunit]:
            length = _float(line.findtext("Length"), f"{path}: CalibrationLine Length", problems)
            seg = line.find("Segment")
            a = _point(seg.findtext("A") if seg is not None else None, f"{path}: CalibrationLine Segment A", problems)
            b = _point(seg.findtext("B") if seg is not None else None, f"{path}: CalibrationLine Segment B", problems)
            if length is not None and a is not None and b is not None:
                px = math.hypot(b[0] - a[0], b[1] - a[1])
                if px <= 0 or length <= 0:
                    problems.append(f"{path}: CalibrationLine: length {length} over {px} px is not a scale")
                else:
                    m_per_px = length * length_to_m(KINOVEA_UNITS[kunit], str(path)) / px
                    source["m_per_px"] = f"CalibrationLine {length:g} {KINOVEA_UNITS[kunit]} over {px:.2f} px"
    return m_per_px


def _tracks(root, path: Path, per_frame: float | None, first: float, problems: list[str]) -> dict:
    """Return each track's points: (frames, x, y) in pixels, the frames from the timestamps."""
    tracks: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    for track in root.findall("Tracks/Track"):
        name = track.get("name")
        if name is None:
            label = track.find("MainLabel")
            name = label.get("Text") if label is not None else ""
        at = f"{path}: track {name!r}"
        if name in tracks:
            problems.append(f"{at}: two tracks have this name (rename one in Kinovea)")
            continue
        pts = track.findall("TrackPointList/TrackPoint")
        x, y, t, labels = [], [], [], []
        bad: list[str] = []
        for i, tp in enumerate(pts):
            parts = (tp.text or "").split(";")
            where = f"{at}, point {i + 1}"
            if len(parts) < 3:
                bad.append(f"{where}: {tp.text!r} is not 'x;y;t'")
                continue
            vals = [_float(p, where, bad) for p in parts[:3]]
            if None in vals:
                continue
            x.append(vals[0])
            y.append(vals[1])
            t.append(vals[2])
            labels.append(f"{where} (t = {parts[2].strip()})")
        problems += bad[:3] + ([f"{at}: ... and {len(bad) - 3} more such problems"] if len(bad) > 3 else [])
        if per_frame is None or bad:
            continue
        frames, fp = whole_frames((np.array(t) - first) / per_frame, "its timestamp", labels, tol=0.01)
        problems += fp
        seen: dict[int, str] = {}
        for f, lab in zip(frames, labels, strict=True):
            if int(f) in seen:
                problems.append(f"{lab}: frame {int(f)} marked twice (also {seen[int(f)]}; {DUPLICATE_RULE})")
            seen.setdefault(int(f), lab)
        tracks[name] = (frames, np.array(x, dtype=float), np.array(y, dtype=float))
    return tracks
