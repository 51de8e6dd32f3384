"""Data tables the tools export: Tracker's "Export Data" text and Kinovea's CSV trajectory export.

Neither holds the camera's settings, so the config states them: the time unit (``s``, ``ms``,
``us`` or ``frames``), the length unit (``m``, ``cm``, ``mm``, ``in``, ``ft``, or ``px`` for
image pixels), the direction of y (``up`` or ``down``), the frame rate and the pixel scale.
Times become frames (``t * fps``, whole to 0.05 frame, else the row is named); lengths become
pixels at the stated scale, y downward.

* **Tracker** (``ExportDataDialog``): an optional ``#multi:`` line; a row of track names (a
  delimiter, then each name followed by one delimiter per column of that track); a row of column
  names (``t``, then ``x``, ``y``... per track); then one row per frame. Delimiter: tab, comma,
  semicolon or space; a decimal comma when the delimiter is not a comma. Each track's ``x`` and
  ``y`` columns are read; empty cells are frames without a mark.
* **Kinovea** (``ExporterCSVTrajectory``): a header ``"Time","<track>/0/X","<track>/0/Y",...``,
  quoted cells, separator ``,`` or ``;`` (``;`` with a decimal comma); empty cells are frames
  without a point.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import TIME_UNITS, FileTracks, FormatError, length_to_m, read_limited, whole_frames

if TYPE_CHECKING:
    import os

TABLE_UNIT_KEYS = ("time", "length", "y")


def check_units(units: object, where: str) -> list[str]:
    """Problems of a table's ``units`` block (time, length, y: all required, no defaults)."""
    if not isinstance(units, dict):
        return [
            f"{where}: missing: a table holds no settings; give units: "
            "{time: s|ms|us|frames, length: m|cm|mm|in|ft|px, y: up|down}"
        ]
    problems = [
        f"{where}.{k}: missing (a table does not say it; no default)" for k in TABLE_UNIT_KEYS if k not in units
    ]
    if "time" in units and units["time"] not in (*TIME_UNITS, "frames"):
        problems.append(f"{where}.time: {units['time']!r} is not s, ms, us or frames")
    if "length" in units and units["length"] != "px":
        try:
            length_to_m(units["length"], f"{where}.length")
        except ValueError as exc:
            problems.append(f"{exc} or px")
    if "y" in units and units["y"] not in ("up", "down"):
        problems.append(f"{where}.y: {units['y']!r} is not up or down")
    return problems


def _read_text(path: Path) -> str:
    raw = read_limited(path)
    for enc in ("utf-8-sig", "cp1252"):
        try:
            return raw.decode(enc)
        except UnicodeDecodeError:
            continue
    raise FormatError([f"{path}: not a text file"])


def _num(cell: str, decimal_comma: bool) -> float:
    cell = cell.strip().strip('"')
    if decimal_comma:
        cell = cell.replace(",", ".")
    return float(cell)


def _add_row(path, ln: int, cells: list[str], blocks: dict, decimal_comma: bool, names, data, problems) -> None:
    """Add one data row of an exported table to ``data`` (track -> lists of t, x, y and row labels).

    ``blocks`` maps each track to its (x, y) column indices; ``names`` are the table's names of
    the time, x and y columns, for messages. A cell that is not a finite number is a problem
    naming the file, the line and the track; a track with both cells empty is not in this row.
    """
    time_name, x_name, y_name = names
    try:
        t = _num(cells[0], decimal_comma)
    except ValueError:
        problems.append(f"{path}: line {ln}, column {time_name}: {cells[0]!r} is not a number")
        return
    for name, (cx, cy) in blocks.items():
        sx = cells[cx].strip() if cx < len(cells) else ""
        sy = cells[cy].strip() if cy < len(cells) else ""
        if not sx and not sy:
            continue
        try:
            x, y = _num(sx, decimal_comma), _num(sy, decimal_comma)
        except ValueError:
            problems.append(f"{path}: line {ln}, track {name!r}: {x_name} {sx!r}, {y_name} {sy!r} are not numbers")
            continue
        if not (np.isfinite(x) and np.isfinite(y)):
            problems.append(f"{path}: line {ln}, track {name!r}: {x_name} {sx!r}, {y_name} {sy!r} are not finite")
            continue
        for lst, v in zip(data[name], (t, x, y, f"{path}: line {ln}, track {name!r}"), strict=True):
            lst.append(v)


def _to_file_tracks(path, cols, units, fps, m_per_px, what) -> FileTracks:
    """(name -> (t, x, y, row labels)) in the table's units -> FileTracks in pixels and frames."""
    problems: list[str] = []
    t_all = np.concatenate([c[0] for c in cols.values()]) if cols else np.array([])
    if units["time"] == "frames":
        scale_t = 1.0
    else:
        scale_t = TIME_UNITS[units["time"]] * fps
    t0 = t_all.min() if t_all.size else 0.0
    per_px = 1.0 if units["length"] == "px" else length_to_m(units["length"], str(path)) / m_per_px
    sign = -1.0 if units["y"] == "up" else 1.0
    tracks = {}
    hint = _time_unit_hint(path, cols, t0, units["time"], fps)
    if hint:
        raise FormatError([hint])
    for name, (t, x, y, labels) in cols.items():
        frames, fp = whole_frames((t - t0) * scale_t, f"time {what}", labels)
        problems += fp
        tracks[name] = (frames, x * per_px, sign * y * per_px)
    if problems:
        problems.append(
            f"{path}: times are not whole frames at {fps:g} fps (units.time {units['time']!r}): "
            "is the frame rate or the time unit wrong?"
        )
        raise FormatError(problems)
    src = {"units": f"config: time {units['time']}, length {units['length']}, y {units['y']}"}
    return FileTracks(path=str(path), tracks=tracks, fps=None, m_per_px=None, source=src)


def _frame_step(t: np.ndarray, t0: float, scale: float) -> float | None:
    """Median step between a track's rows in frames at ``scale`` (None: the times are not whole frames there)."""
    f = (np.sort(t) - t0) * scale
    if f.size < 3 or not np.all(np.abs(f - np.round(f)) <= 0.05):
        return None
    return float(np.median(np.diff(np.round(f))))


def _time_unit_hint(path, cols: dict, t0: float, stated: str, fps: float) -> str:
    """Return a line naming ``units.time`` when another unit gives one frame per row and the stated one does not.

    A table's rows are its video's frames: read in the stated unit, the times of each track step by one
    frame. Steps of 1000 frames (times in ms read as s) or of 0 (s read as ms: every row the same frame)
    point to the time unit, not to typos in the frames or marks given twice.
    """
    units = {**{u: sec * fps for u, sec in TIME_UNITS.items()}, "frames": 1.0}
    steps = {u: [_frame_step(c[0], t0, k) for c in cols.values()] for u, k in units.items()}
    if all(st == 1.0 for st in steps[stated] if st is not None) and any(st is not None for st in steps[stated]):
        return ""
    fits = [u for u, st in steps.items() if u != stated and st and all(v == 1.0 for v in st)]
    if not fits:
        return ""
    seen = [v for v in steps[stated] if v is not None]
    how = f"rows {seen[0]:g} frames apart" if seen else "times that are not whole frames"
    return (
        f"{path}: units.time says {stated!r}, which gives {how} at {fps:g} fps; read as {fits[0]!r} the times "
        f"step by one frame per row: is units.time wrong (the table's time column is in {fits[0]})?"
    )


def read_tracker_table(path: str | os.PathLike[str], units: dict, fps: float, m_per_px: float) -> FileTracks:
    """Read a data table exported by Tracker (File > Export > Data)."""
    path = Path(path)
    lines = [ln for ln in _read_text(path).splitlines()]
    i = 0
    while i < len(lines) and (not lines[i].strip() or lines[i].startswith("#")):
        i += 1
    if i + 1 >= len(lines):
        raise FormatError([f"{path}: not a Tracker data table (no row of track names and of column names)"])
    names_row, header = lines[i], lines[i + 1]
    delim = next(
        (d for d in ("\t", ";", ",", " ") if header.split(d, 1)[0].strip() in ("t", "frame") and d in header), None
    )
    if delim is None:
        raise FormatError(
            [
                f"{path}: line {i + 2}: not a Tracker data table header (it starts with t and a delimiter: "
                f"{header[:40]!r})"
            ]
        )
    decimal_comma = delim != ","
    names = names_row.split(delim)
    heads = [h.strip() for h in header.split(delim)]
    starts = [(j, n.strip()) for j, n in enumerate(names) if n.strip()]
    problems: list[str] = []
    blocks = {}
    for k, (j, name) in enumerate(starts):
        end = starts[k + 1][0] if k + 1 < len(starts) else len(heads)
        cols = {heads[c]: c for c in range(j, min(end, len(heads)))}
        if "x" not in cols or "y" not in cols:
            problems.append(f"{path}: track {name!r} has no x and y columns (columns: {', '.join(cols) or 'none'})")
            continue
        if name in blocks:
            problems.append(f"{path}: track {name!r} appears twice in the header")
            continue
        blocks[name] = (cols["x"], cols["y"])
    data: dict[str, tuple[list, list, list, list]] = {n: ([], [], [], []) for n in blocks}
    for ln, line in enumerate(lines[i + 2 :], start=i + 3):
        if not line.strip() or line.startswith("#"):
            continue
        _add_row(path, ln, line.split(delim), blocks, decimal_comma, ("t", "x", "y"), data, problems)
    if problems:
        raise FormatError(problems)
    cols = {n: (np.array(t), np.array(x), np.array(y), lab) for n, (t, x, y, lab) in data.items()}
    return _to_file_tracks(path, cols, units, fps, m_per_px, "t")


def read_kinovea_table(path: str | os.PathLike[str], units: dict, fps: float, m_per_px: float) -> FileTracks:
    """Read a Kinovea trajectory CSV export (File > Export to spreadsheet > trajectories)."""
    path = Path(path)
    text = _read_text(path)
    first = text.split("\n", 1)[0]
    delim = ";" if first.count(";") > first.count(",") else ","
    rows = list(csv.reader(io.StringIO(text), delimiter=delim))
    if not rows or not rows[0] or rows[0][0].strip() != "Time":
        raise FormatError([f'{path}: line 1: not a Kinovea trajectory export (the header starts with "Time")'])
    head = [h.strip() for h in rows[0]]
    problems: list[str] = []
    blocks: dict[str, list] = {}
    for c, h in enumerate(head[1:], start=1):
        parts = h.rsplit("/", 2)
        if len(parts) < 2 or parts[-1] not in ("X", "Y"):
            problems.append(f"{path}: line 1, column {c + 1}: {h!r} is not '<track>/<point>/X' or '.../Y'")
            continue
        key = parts[0] if len(parts) == 2 or parts[1] == "0" else f"{parts[0]}/{parts[1]}"
        blocks.setdefault(key, [None, None])[0 if parts[-1] == "X" else 1] = c
    for k, (cx, cy) in blocks.items():
        if cx is None or cy is None:
            problems.append(f"{path}: line 1: track {k!r} lacks its {'X' if cx is None else 'Y'} column")
    if problems:
        raise FormatError(problems)
    decimal_comma = delim == ";"
    data: dict[str, tuple[list, list, list, list]] = {n: ([], [], [], []) for n in blocks}
    for ln, cells in enumerate(rows[1:], start=2):
        if not any(c.strip() for c in cells):
            continue
        _add_row(path, ln, cells, blocks, decimal_comma, ("Time", "X", "Y"), data, problems)
    if problems:
        raise FormatError(problems)
    cols = {n: (np.array(t), np.array(x), np.array(y), lab) for n, (t, x, y, lab) in data.items()}
    return _to_file_tracks(path, cols, units, fps, m_per_px, "Time")
