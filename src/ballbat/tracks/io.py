"""Read a lab's raw camera tracks (CSV or NetCDF) (docs/tracks.md; the stage :mod:`ballbat.stages.render` writes them).

``tracks.csv`` is long: ``impact_id,camera,point,frame,x_px,y_px``, one row per tracked
point per frame (a NetCDF file holds the same variables along one dimension ``row``).
``impacts.csv`` has one row per impact: ``impact_id,bat,ball``. A NetCDF tracks file that
also holds ``impact_id``, ``bat`` and ``ball`` along a dimension ``impact`` (as the
rendered synthetic tracks do) needs no impacts file. Everything is checked before
anything is computed, and every problem is reported at once
(:class:`~ballbat.properties.InputError`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..properties import NETCDF_SUFFIXES as _NC
from ..properties import InputError, read_table
from .checks import check_frame_runs
from .data import (
    POINTS,
    Camera,
    Rig,
    TrackBlocks,
    Tracks,
    blocks_problems,
    dense_problems,
    plan_blocks,
    to_dense,
    track_spans,
)
from .validate import (
    IMPACT_COLUMNS,
    TRACK_COLUMNS,
    check_cameras,
    check_header,
    check_impact_rows,
    check_track_rows,
)

if TYPE_CHECKING:
    import os
    from collections.abc import Sequence


def long_csv_text(cols: dict, extra: Sequence[str] = ()) -> str:
    """Return the long tracks table as CSV text, as ``load_tracks`` reads it.

    ``cols`` holds :data:`~ballbat.tracks.validate.TRACK_COLUMNS` (and any ``extra``
    columns, written after them), one array each. Rows sorted by impact, camera, point and
    frame; numbers written in full (``repr``), a NaN as an empty cell; cells quoted where needed.
    """
    import csv
    import io

    names = [*TRACK_COLUMNS, *extra]
    order = np.lexsort(tuple(np.asarray(cols[k]) for k in ("frame", "point", "camera", "impact_id")))

    def cell(v):
        if isinstance(v, (float, np.floating)):
            return "" if not np.isfinite(v) else repr(float(v))
        return str(int(v)) if isinstance(v, (int, np.integer)) else str(v)

    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(names)
    w.writerows([cell(cols[k][i]) for k in names] for i in order)
    return out.getvalue()


def _truth_from_nc(path: Path) -> dict[str, np.ndarray]:
    if path.suffix.lower() not in _NC:
        return {}
    with xr.open_dataset(path) as ds:
        return {k: ds[k].values for k in ds.data_vars if k.startswith("truth_") and ds[k].dims == ("impact",)}


def cameras_from_config(cfg: dict, where: str = "tracks") -> tuple[dict[str, Camera], Rig]:
    """Camera settings and rig of a tracked dataset's config block, checked whole.

    Parameters
    ----------
    cfg : dict
        The block (``cameras``, ``rig``; other keys are ignored), validated, every default
        filled (the schema's ``m_per_px_err``: 0).
    where : str
        Config key of the block, for messages.

    Returns
    -------
    (cameras, rig)
    """
    problems = check_cameras(cfg, where)
    if problems:
        raise InputError(problems)
    cams = {
        name: Camera(
            fps=float(c["fps"]),
            m_per_px=float(c["m_per_px"]),
            mirror=bool(c["mirror"]),
            m_per_px_err=float(c["m_per_px_err"]),
            fps_err=float(c["fps_err"]),
            exposure_s=float(c["exposure_us"]) * 1e-6,
        )
        for name, c in cfg["cameras"].items()
    }
    rig = Rig.from_inches(**{k: float(v) for k, v in cfg["rig"].items()})
    return cams, rig


def read_impacts(
    ipath: Path, balls: dict | None, bats: dict | None, more_columns: bool = False
) -> tuple[dict[str, str] | None, list, list[str]]:
    """Read and check a tracks dataset's impacts table: return (impact id -> row label, rows, problems).

    The impacts are None when the table cannot be read or its header is wrong; ``more_columns``
    allows columns beyond :data:`~ballbat.tracks.validate.IMPACT_COLUMNS` (a NetCDF's own
    impact table holds the truth too).
    """
    problems: list[str] = []
    impacts: dict[str, str] | None = None
    irows: list = []
    try:
        iheader, irows = read_table(ipath, IMPACT_COLUMNS, "impact")
        hp = check_header(ipath, iheader, IMPACT_COLUMNS)
        if more_columns:
            hp = [p for p in hp if "unknown column" not in p]
        problems += hp
        if not hp:
            impacts, rp = check_impact_rows(ipath, irows, balls, bats)
            problems += rp
    except InputError as exc:
        problems += exc.problems
    return impacts, irows, problems


def load_tracks(
    tracks_path: str | os.PathLike[str],
    impacts_path: str | os.PathLike[str] | None = None,
    balls: dict | None = None,
    bats: dict | None = None,
) -> Tracks | TrackBlocks:
    """Read and check a tracks file and its impacts file; return dense tracks (in blocks when one would be too large).

    Parameters
    ----------
    tracks_path : path-like
        ``tracks.csv`` or ``.nc`` (long format).
    impacts_path : path-like, optional
        ``impacts.csv`` (``impact_id,bat,ball``); default: the tracks NetCDF file's own
        ``impact`` table.
    balls, bats : dict, optional
        Property tables; balls and bats not in them are reported.

    Returns
    -------
    Tracks or TrackBlocks
        One :class:`~ballbat.tracks.data.Tracks` when padding every impact to the longest track
        is cheap (:data:`~ballbat.tracks.data.BLOCK_BYTES`), else blocks of impacts.

    Raises
    ------
    ballbat.properties.InputError
        Every problem of both files at once.
    """
    tracks_path = Path(tracks_path)
    problems: list[str] = []
    ipath = Path(impacts_path) if impacts_path is not None else tracks_path
    # the NetCDF's own impact table may hold more (truth_*)
    impacts, irows, problems = read_impacts(ipath, balls, bats, more_columns=impacts_path is None)
    if not problems and impacts is not None:
        fast = (_fast_nc if tracks_path.suffix.lower() in _NC else _fast_csv)(tracks_path, impacts)
        if fast is not None:  # well-formed: skip the row-by-row checks (they would find nothing)
            labels = fast.pop("label")
            runs = check_frame_runs(tracks_path, fast["impact_id"], fast["camera"], fast["frame"], labels)
            if runs:
                raise InputError(runs)
            return _assemble(fast, irows, ipath if impacts_path is None else None, str(tracks_path))
    try:
        header, rows = read_table(tracks_path, TRACK_COLUMNS, "row")
    except InputError as exc:
        raise InputError(problems + exc.problems) from None
    hp = check_header(tracks_path, header, TRACK_COLUMNS)
    problems += hp
    if hp:
        raise InputError(problems)
    cols, rp = check_track_rows(tracks_path, rows, impacts, ipath)
    problems += rp
    if not rp:  # a frame far outside its impact's run: named here, before any array is sized
        problems += check_frame_runs(tracks_path, cols["impact_id"], cols["camera"], cols["frame"], cols["label"])
    if problems:
        raise InputError(problems)
    cols = {k: np.asarray(cols[k]) for k in TRACK_COLUMNS}
    return _assemble(cols, irows, ipath if impacts_path is None else None, str(tracks_path))


def _fast_nc(path: Path, impacts: dict) -> dict | None:
    """Return the long columns of a NetCDF tracks file when every vectorised check passes, else None."""
    try:
        with xr.open_dataset(path) as ds:
            if "row" not in ds.dims or any(c not in ds or ds[c].dims != ("row",) for c in TRACK_COLUMNS):
                return None
            cols = {c: ds[c].values for c in TRACK_COLUMNS}
    except (OSError, ValueError):
        return None
    out = _fast_checked(cols, impacts)
    if out is not None:
        out["label"] = np.char.add("row ", np.arange(out["frame"].size).astype(str))
    return out


def _fast_csv(path: Path, impacts: dict) -> dict | None:
    """Return the long columns of a CSV tracks file when every vectorised check passes, else None.

    Columns, not a dict per row: a plain file (commas, no quotes, no spaces, as programs write
    them) of 10^6 rows is checked in seconds, and one whose track is too long to lay out
    is named before any row-by-row work. Anything else (a semicolon file, a quoted cell, a
    missing or surplus cell, a text where a number belongs) returns None, and the row-by-row
    checks read it as labs make them and name what is wrong.
    """
    from ..properties import without_check_line

    try:
        text = without_check_line(path, path.read_bytes().decode("utf-8-sig"))
    except (InputError, OSError, UnicodeDecodeError):
        return None
    if any(ch in text for ch in '"; \t\r'):
        return None
    lines = text.split("\n")
    line_no = [k for k, ln in enumerate(lines) if ln]
    if len(line_no) < 2:
        return None
    header = lines[line_no[0]].split(",")
    rows = [lines[k] for k in line_no[1:]]
    if check_header(path, header, TRACK_COLUMNS) or any(ln.count(",") != len(header) - 1 for ln in rows):
        return None
    flat = ",".join(rows).split(",")
    cols = {c: flat[header.index(c) :: len(header)] for c in TRACK_COLUMNS}
    try:
        cols.update({c: np.fromiter(map(float, cols[c]), float, len(rows)) for c in ("frame", "x_px", "y_px")})
    except ValueError:
        return None
    cols.update({c: np.array(cols[c]) for c in ("impact_id", "camera", "point")})
    out = _fast_checked(cols, impacts)
    if out is not None:
        out["label"] = np.array([f"row {k + 1}" for k in line_no[1:]])
    return out


def _fast_checked(cols: dict, impacts: dict) -> dict | None:
    """Return typed long columns when every vectorised check of the row checks passes, else None."""
    cam, point, iid = (np.asarray(cols[c]).astype(str, copy=False) for c in ("camera", "point", "impact_id"))
    frame = np.asarray(cols["frame"]).astype(float)
    x, y = np.asarray(cols["x_px"]).astype(float), np.asarray(cols["y_px"]).astype(float)
    ok = np.isfinite(frame) & (frame == np.round(frame)) & (np.abs(frame) < 2.0**53)
    if not (ok.all() and np.isfinite(x).all() and np.isfinite(y).all()):
        return None
    pairs = [f"{c}/{p}" for c, pts in POINTS.items() for p in pts]
    cams, cam_code = np.unique(cam, return_inverse=True)
    points, point_code = np.unique(point, return_inverse=True)
    names = np.char.add(np.char.add(cams[:, None], "/"), points[None, :])
    ids, id_code = np.unique(iid, return_inverse=True)
    if not (np.isin(names, pairs)[cam_code, point_code].all() and np.isin(ids, list(impacts)).all()):
        return None
    track = id_code.astype(np.int64) * names.size + cam_code * points.size + point_code
    f = frame.astype(np.int64)
    order = np.lexsort((f, track))
    ts, fs = track[order], f[order]
    if np.any((ts[1:] == ts[:-1]) & (fs[1:] == fs[:-1])):
        return None  # a frame twice: the row checks name both rows
    if np.unique(track).size != len(impacts) * len(pairs):
        return None  # a camera or point missing somewhere: the row checks say where
    return {"impact_id": iid, "camera": cam, "point": point, "frame": f, "x_px": x, "y_px": y}


def _assemble(cols: dict, irows, truth_path, source: str = "tracks") -> Tracks | TrackBlocks:
    """Lay checked long rows out as dense tracks; a track too long is named first (``source``: the file).

    One :class:`Tracks` when padding every impact to the longest track fits
    :data:`~ballbat.tracks.data.BLOCK_BYTES`, else :class:`TrackBlocks` (:func:`~ballbat.tracks.data.plan_blocks`).
    """
    ids = np.array([row["impact_id"] for _, row in irows], dtype=str)
    index = {iid: i for i, iid in enumerate(ids.tolist())}
    n = len(ids)
    uniq, inv = np.unique(np.asarray(cols["impact_id"]).astype(str), return_inverse=True)
    impact_index = np.array([index[u] for u in uniq], dtype=np.int64)[inv]
    camera, frame = np.asarray(cols["camera"]).astype(str), np.asarray(cols["frame"], dtype=np.int64)
    too_large = dense_problems(ids, impact_index, camera, frame, source)
    if too_large:
        raise InputError(too_large)
    point = np.asarray(cols["point"]).astype(str)
    x, y = np.asarray(cols["x_px"], dtype=float), np.asarray(cols["y_px"], dtype=float)
    tracks = Tracks(
        impact_id=ids,
        ball=np.array([row["ball"] for _, row in irows], dtype=str),
        bat=np.array([row["bat"] for _, row in irows], dtype=str),
        cameras={},
        truth=_truth_from_nc(truth_path) if truth_path is not None else {},
    )
    spans = {c: v[2] for c, v in track_spans(impact_index, camera, frame, n).items()}
    plan = plan_blocks(spans)
    too_large = blocks_problems(spans, plan, source)
    if too_large:
        raise InputError(too_large)
    if len(plan) == 1:
        tracks.cameras = to_dense(impact_index, camera, point, frame, x, y, n)
        return tracks
    blocks = []
    position = np.empty(n, dtype=np.int64)
    for idx in plan:
        position[idx] = np.arange(idx.size)
        rows = np.isin(impact_index, idx)
        sub = Tracks(
            tracks.impact_id[idx], tracks.ball[idx], tracks.bat[idx], {}, {k: v[idx] for k, v in tracks.truth.items()}
        )
        ii = position[impact_index[rows]]
        sub.cameras = to_dense(ii, camera[rows], point[rows], frame[rows], x[rows], y[rows], idx.size)
        blocks.append(sub)
    return TrackBlocks(blocks, plan)
