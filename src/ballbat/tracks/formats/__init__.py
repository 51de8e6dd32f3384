"""Read the files tracking tools write: Tracker (.trk, .trz, data tables) and Kinovea (.kva, exports).

Each reader returns a :class:`FileTracks`: every named track of one file as frame numbers and
pixel coordinates in ballbat's convention (x to the right, y downward, one pixel scale for
both axes), with the camera settings the file holds (frame rate, pixel scale) and a note of
where each came from. :mod:`.layout` lays a lab's folder of such files (one per impact and
camera) out as ballbat's long tracks. See docs/tracks.md ("Files of tracking tools").

* :mod:`.tracker` -- Tracker project files (``.trk``, XML) and archives (``.trz``).
* :mod:`.kinovea` -- Kinovea annotation files (``.kva``, XML).
* :mod:`.tables` -- Tracker's exported data tables and Kinovea's CSV exports (no settings:
  the config states the units, the axis direction, the frame rate and the pixel scale).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: Metres per length unit, by every name the tools (and a config) use for it.
LENGTH_UNITS = {
    "m": 1.0,
    "meter": 1.0,
    "meters": 1.0,
    "metre": 1.0,
    "metres": 1.0,
    "cm": 0.01,
    "centimeters": 0.01,
    "mm": 0.001,
    "millimeters": 0.001,
    "in": 0.0254,
    "inch": 0.0254,
    "inches": 0.0254,
    "ft": 0.3048,
    "feet": 0.3048,
    "yd": 0.9144,
    "yards": 0.9144,
}
#: The one rule for a frame marked twice in one track, in every reader (Tracker's ``.trk``/``.trz``, its
#: tables, Kinovea's ``.kva`` and exports, a lab's long CSV): the file is refused, naming the track and
#: the frame. No reader picks one of the two marks (Tracker's XML read as a map used to keep the later).
DUPLICATE_RULE = "a frame is marked once per track: ballbat refuses a duplicated mark rather than pick one; delete one"
#: Seconds per time unit of a table (``frames``: the time column counts frames).
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6}


#: The largest tool file (or ``.trz`` archive member) read, in bytes: checked before reading it.
#: 32 MiB holds some 200 000 marks (a lab's file of one impact and camera holds a few thousand).
MAX_FILE_BYTES = 32 * 2**20
#: The largest compression ratio of a ``.trz`` member (uncompressed / compressed size): Tracker's XML
#: compresses some 10 times; far more is an archive built to blow up when read.
MAX_COMPRESSION_RATIO = 200


class FormatError(Exception):
    """Problems of one file (each naming the file, the track or row, and what is wrong)."""

    def __init__(self, problems: list[str]):
        super().__init__("\n".join(problems))
        self.problems = list(problems)


def size_problem(name: str, size: int) -> str | None:
    """Why a file (or archive member) of ``size`` bytes is not read (None: small enough)."""
    if size <= MAX_FILE_BYTES:
        return None
    return (
        f"{name}: {size / 2**20:.0f} MiB, more than the {MAX_FILE_BYTES // 2**20} MiB a tool file may hold "
        "(one impact and one camera per file); not read"
    )


def read_limited(path: Path) -> bytes:
    """Return the bytes of a tool file, refused (named) when it is larger than :data:`MAX_FILE_BYTES`."""
    try:
        problem = size_problem(str(path), path.stat().st_size)
        if problem:
            raise FormatError([problem])
        with open(path, "rb") as fh:
            data = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise FormatError([f"{path}: cannot be read ({exc})"]) from None
    if len(data) > MAX_FILE_BYTES:  # a file that grew, or a device: never more than the limit in memory
        raise FormatError([size_problem(str(path), len(data)) or f"{path}: too large"])
    return data


@dataclass
class FileTracks:
    """The tracks of one file, in ballbat's pixel convention, and the settings the file holds.

    ``tracks`` maps the tool's track name to ``(frame, x_px, y_px)`` arrays (frames whole,
    coordinates finite). ``fps``, ``m_per_px`` and ``exposure_s`` (a frame's exposure time, s: a
    clip's) are None when the file does not hold them; ``source`` says where each setting came
    from (for the import report).
    """

    path: str
    tracks: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]
    fps: float | None = None
    m_per_px: float | None = None
    source: dict[str, str] = field(default_factory=dict)
    exposure_s: float | None = None


def whole_frames(values: np.ndarray, what: str, labels: list[str], tol: float = 0.05) -> tuple[np.ndarray, list[str]]:
    """Round ``values`` to whole frame numbers; a value further than ``tol`` from one is a problem per label."""
    values = np.asarray(values, dtype=float)
    rounded = np.round(values)
    bad = ~np.isfinite(values) | (np.abs(values - rounded) > tol)
    problems = [f"{labels[i]}: {what} is {values[i]:.3f} frames, not a whole frame" for i in np.flatnonzero(bad)[:5]]
    if bad.sum() > 5:
        problems.append(f"... and {int(bad.sum()) - 5} more such rows")
    out = np.where(bad, 0, rounded).astype(np.int64)
    return out, problems


def finite_number(text: str | None, what: str, problems: list[str], integer: bool = False) -> float | int | None:
    """Return a tracking file's number (``integer``: a whole number), or None with the problem added.

    ``what`` names the file and the field; the message is ``"{what} {text!r} is not a number"``
    (or ``is not finite``).
    """
    try:
        v = int((text or "").strip()) if integer else float((text or "").strip())
    except ValueError:
        problems.append(f"{what} {text!r} is not a number")
        return None
    if not math.isfinite(v):
        problems.append(f"{what} {text!r} is not finite")
        return None
    return v


def length_to_m(unit: str, where: str) -> float:
    """Metres per ``unit``; a ValueError naming ``where`` when the unit is unknown."""
    key = str(unit).strip().lower()
    if key not in LENGTH_UNITS:
        raise ValueError(f"{where}: unknown length unit {unit!r} (known: m, cm, mm, in, ft, yd)")
    return LENGTH_UNITS[key]


def close(a: float, b: float, rel: float = 1e-3) -> bool:
    """Whether two settings agree to ``rel`` (relative)."""
    return math.isclose(a, b, rel_tol=rel)
