"""Tracker (Open Source Physics) project files: ``.trk`` (XML) and ``.trz`` (a zip holding one).

A project is an OSP ``XMLControl``: ``<object class="...TrackerPanel">`` with ``<property
name=... type=...>`` children. What ballbat reads:

* ``videoclip`` (``VideoClip``): ``startframe``, ``stepsize``, ``stepcount``;
* ``clipcontrol`` (``ClipControl``): ``delta_t``, the frame interval in ms (fps = 1000/delta_t);
* ``coords`` (``ImageCoordSystem``): ``framedata`` entries with ``xorigin``, ``yorigin`` (image
  pixels), ``angle`` (degrees, the world x-axis counter-clockwise from the image x-axis),
  ``xscale``, ``yscale`` (pixels per length unit);
* ``length_unit`` (``m``, ``cm``, ``mm``, ``in``, ``ft``);
* ``tracks``: each ``PointMass``'s ``name`` and ``framedata`` array. Entry ``[n]`` is the mark
  at video frame ``n`` (Tracker indexes a track's steps by frame number) with ``x``, ``y`` in
  image pixels (y downward). Marks must lie on the clip's steps: frame
  ``startframe + k * stepsize``, ``0 <= k < stepcount``.

The pixels are turned into the coordinate system's axes (rotated by ``angle`` about the origin,
y scaled by ``xscale/yscale``), so that ballbat's x-axis is the one the lab set in Tracker; with
``angle`` 0 and equal scales they are the image pixels unchanged.
"""

from __future__ import annotations

import math
import zipfile
from pathlib import Path
from typing import TYPE_CHECKING
from xml.etree import ElementTree as ET

import numpy as np

from . import (
    DUPLICATE_RULE,
    MAX_COMPRESSION_RATIO,
    MAX_FILE_BYTES,
    FileTracks,
    FormatError,
    finite_number,
    length_to_m,
    read_limited,
    size_problem,
)

if TYPE_CHECKING:
    import os

POINT_MASS = "org.opensourcephysics.cabrillo.tracker.PointMass"


def _props(obj: ET.Element) -> dict[str, ET.Element]:
    return {p.get("name"): p for p in obj.findall("property")}


def _child_object(prop: ET.Element | None) -> ET.Element | None:
    return None if prop is None else prop.find("object")


def _number(props: dict, name: str, where: str, problems: list[str], integer: bool = False):
    p = props.get(name)
    if p is None:
        return None
    return finite_number((p.text or "").strip(), f"{where}: {name}", problems, integer)


def _array(prop: ET.Element, at: str, problems: list[str]) -> dict[int, ET.Element]:
    """Return the entries ``[n]`` of an array property by ``n``.

    An entry given twice is a problem (:data:`ballbat.tracks.formats.DUPLICATE_RULE`): never resolved to one.
    """
    out: dict[int, ET.Element] = {}
    twice: list[int] = []
    for item in prop.findall("property"):
        name = item.get("name", "")
        if name.startswith("[") and name.endswith("]") and name[1:-1].isdigit():
            obj = item.find("object")
            if obj is not None:
                if int(name[1:-1]) in out:
                    twice.append(int(name[1:-1]))
                out[int(name[1:-1])] = obj
    if twice:
        frames = ", ".join(map(str, sorted(set(twice))[:5]))
        problems.append(f"{at}: frame(s) {frames} marked twice ({DUPLICATE_RULE})")
    return out


def read_trk_text(text: bytes | str, path: str) -> FileTracks:
    """Parse a Tracker project's XML (the text of a ``.trk``); ``path`` names it in messages."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise FormatError([f"{path}: not a Tracker project (XML does not parse: {exc})"]) from None
    if root.tag != "object" or not str(root.get("class", "")).endswith("TrackerPanel"):
        raise FormatError([f"{path}: not a Tracker project (the root is not a TrackerPanel object)"])
    problems: list[str] = []
    top = _props(root)
    source: dict[str, str] = {}
    clip = _clip_steps(top, path, problems)
    fps = _frame_rate(top, path, problems, source)
    m_per_px, axes = _coordinate_system(top, path, problems, source)
    tracks = _point_masses(root, path, clip, axes, problems)
    if problems:
        raise FormatError(problems)
    _xo, _yo, angle, ratio = axes
    if angle or ratio != 1.0:
        source["axes"] = (
            f"pixels turned into the coordinate system's axes (angle {angle:g} deg, xscale/yscale {ratio:g})"
        )
    return FileTracks(path=path, tracks=tracks, fps=fps, m_per_px=m_per_px, source=source)


def _clip_steps(top: dict, path: str, problems: list[str]) -> tuple[int, int, int | None]:
    """Return the video clip's first frame, step and number of steps (None: not given)."""
    clip = _child_object(top.get("videoclip"))
    cp = _props(clip) if clip is not None else {}
    start = _number(cp, "startframe", f"{path}: videoclip", problems, integer=True)
    step = _number(cp, "stepsize", f"{path}: videoclip", problems, integer=True)
    count = _number(cp, "stepcount", f"{path}: videoclip", problems, integer=True)
    start = 0 if start is None else start
    step = 1 if step is None else step
    if step < 1:
        problems.append(f"{path}: videoclip: stepsize {step} must be at least 1")
        step = 1
    return start, step, count


def _frame_rate(top: dict, path: str, problems: list[str], source: dict) -> float | None:
    """Return the frame rate the clip control's delta_t gives (None: not in the file)."""
    fps = None
    cc = _child_object(top.get("clipcontrol"))
    dt = _number(_props(cc), "delta_t", f"{path}: clipcontrol", problems) if cc is not None else None
    if dt is not None:
        if dt <= 0:
            problems.append(f"{path}: clipcontrol: delta_t {dt} ms must be positive")
        else:
            fps = 1000.0 / dt
            source["fps"] = f"clipcontrol delta_t {dt:g} ms"
    return fps


def _coordinate_system(top: dict, path: str, problems: list[str], source: dict):
    """Return m_per_px (None: no scale or no unit) and the axes (x and y origin, angle in deg, xscale/yscale).

    The coordinate system must be the same in every frame.
    """
    unit_prop = top.get("length_unit")
    unit = (unit_prop.text or "").strip() if unit_prop is not None else None
    m_per_px = None
    xo = yo = 0.0
    angle = 0.0
    ratio = 1.0
    coords = _child_object(top.get("coords"))
    frames_data = (
        _array(_props(coords)["framedata"], f"{path}: coords framedata", problems)
        if coords is not None and "framedata" in _props(coords)
        else {}
    )
    if frames_data:
        values = []
        for n, obj in sorted(frames_data.items()):
            fp = _props(obj)
            at = f"{path}: coords framedata [{n}]"
            vals = tuple(_number(fp, k, at, problems) for k in ("xorigin", "yorigin", "angle", "xscale", "yscale"))
            if None not in vals:
                values.append((n, vals))
        if values:
            n0, (xo, yo, angle, xs, ys) = values[0]
            for n, v in values[1:]:
                if not np.allclose(v, values[0][1], rtol=1e-9, atol=1e-9):
                    problems.append(
                        f"{path}: the coordinate system changes at frame {n} (origin, angle or scale differ from "
                        f"frame {n0}): ballbat needs one fixed coordinate system per file (fix origin, angle and "
                        "scale in Tracker)"
                    )
                    break
            if xs <= 0 or ys <= 0:
                problems.append(f"{path}: coords: xscale {xs} and yscale {ys} must be positive")
            elif unit is None:
                source["scale"] = f"coords xscale {xs:g} px per unit, but no length_unit in the file"
            else:
                try:
                    m_per_px = length_to_m(unit, f"{path}: length_unit") / xs
                    source["m_per_px"] = f"coords xscale {xs:g} px/{unit}"
                except ValueError as exc:
                    problems.append(str(exc))
                ratio = xs / ys
    return m_per_px, (xo, yo, angle, ratio)


def _point_masses(root, path: str, clip: tuple, axes: tuple, problems: list[str]) -> dict:
    """Return each point mass's marks: (frames, x, y) in pixels along the coordinate system's axes.

    A mark must sit on a step of the clip; axes, tapes and other tools are not tracked points.
    """
    start, step, count = clip
    xo, yo, angle, ratio = axes
    tracks: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    items = _props(root).get("tracks")
    for item in items.findall("property") if items is not None else []:
        obj = item.find("object")
        if obj is None or obj.get("class") != POINT_MASS:
            continue  # axes, tapes, calibration sticks, models: not tracked points
        tp = _props(obj)
        name = (tp["name"].text or "").strip() if "name" in tp else ""
        at = f"{path}: track {name!r}"
        if name in tracks:
            problems.append(f"{at}: two point masses have this name (rename one in Tracker)")
            continue
        data = _array(tp["framedata"], at, problems) if "framedata" in tp else {}
        frames, xs_, ys_ = [], [], []
        for n, fobj in sorted(data.items()):
            fp = _props(fobj)
            x = _number(fp, "x", f"{at}, frame {n}", problems)
            y = _number(fp, "y", f"{at}, frame {n}", problems)
            if x is None or y is None:
                if "x" not in fp or "y" not in fp:
                    problems.append(f"{at}, frame {n}: mark without x or y")
                continue
            k = (n - start) / step
            if n < start or k != int(k) or (count is not None and k >= count):
                last = start + step * (count - 1) if count is not None else "..."
                problems.append(
                    f"{at}, frame {n}: the mark is not on a step of the clip (frames {start}, {start + step}, ... "
                    f"{last}): a mark Tracker no longer shows; delete it or widen the clip"
                )
                continue
            frames.append(n)
            xs_.append(x)
            ys_.append(y)
        tracks[name] = (np.array(frames, dtype=np.int64), *_to_axes(np.array(xs_), np.array(ys_), xo, yo, angle, ratio))
    return tracks


def _to_axes(px, py, xo, yo, angle_deg, ratio):
    """Image pixels -> pixels along the coordinate system's axes (x right, y down, x's scale)."""
    if angle_deg == 0 and ratio == 1.0:
        return px.astype(float), py.astype(float)
    a = math.radians(angle_deg)
    u, v = px - xo, -(py - yo) * ratio  # y up, in x's pixels
    wx = math.cos(a) * u + math.sin(a) * v
    wy = -math.sin(a) * u + math.cos(a) * v
    return xo + wx, yo - wy


def read_trk(path: str | os.PathLike[str]) -> FileTracks:
    """Read a ``.trk`` file."""
    path = Path(path)
    return read_trk_text(read_limited(path), str(path))


def read_trz(path: str | os.PathLike[str]) -> FileTracks:
    """Read the one ``.trk`` project inside a ``.trz`` archive."""
    path = Path(path)
    try:
        with zipfile.ZipFile(path) as z:
            names = [n for n in z.namelist() if n.lower().endswith(".trk")]
            if len(names) != 1:
                found = ", ".join(names) if names else "none"
                raise FormatError([f"{path}: a .trz must hold exactly one .trk project (found: {found})"])
            return read_trk_text(_read_member(z, z.getinfo(names[0]), f"{path}:{names[0]}"), f"{path}:{names[0]}")
    except (OSError, zipfile.BadZipFile, EOFError, RuntimeError, NotImplementedError) as exc:
        raise FormatError([f"{path}: not a Tracker archive (.trz is a zip file: {exc})"]) from None


def _read_member(z: zipfile.ZipFile, info: zipfile.ZipInfo, name: str) -> bytes:
    """Return an archive member's bytes, checked before reading: not encrypted, within the size and ratio limits."""
    if info.flag_bits & 0x1:
        raise FormatError([f"{name}: the member is encrypted (password-protected); save the project unencrypted"])
    problem = size_problem(name, info.file_size)
    ratio = info.file_size / max(info.compress_size, 1)
    if problem is None and ratio > MAX_COMPRESSION_RATIO:
        problem = (
            f"{name}: compressed {ratio:.0f} times, more than the {MAX_COMPRESSION_RATIO} a Tracker project "
            "compresses (an archive built to blow up when read?); not read"
        )
    if problem:
        raise FormatError([problem])
    with z.open(info) as fh:
        data = fh.read(MAX_FILE_BYTES + 1)  # the sizes in the header may lie: never more than the limit
    if len(data) > MAX_FILE_BYTES:
        raise FormatError([size_problem(name, len(data)) or f"{name}: too large"])
    return data
