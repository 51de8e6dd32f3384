"""A lab's folder of tool files -> ballbat's long tracks and the camera settings found in them.

One file per impact and camera, named by a pattern (default ``{impact_id}_{camera}.{ext}``;
``camera`` is ``swing`` or ``spin``). ``points`` maps ballbat's points to the tool's track names
(``{ball: ball, bat_tip: tip, dot_a: A, dot_b: B}``); other tracks of a file are left out and
listed. The frame rate and the pixel scale come from the files wherever they hold them; a config
value that contradicts a file is an error naming both; where no file holds one, the config must
give it. Files of one camera calibrated apart (slightly different scales) are brought to one
scale (the config's, or the median of the files'), and the range is reported.
"""

from __future__ import annotations

import re
import statistics
import unicodedata
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..data import BY_EXTENSION, CAMERAS, FORMATS, POINTS, Tracks, tool_file_extensions
from . import DUPLICATE_RULE, FileTracks, FormatError, close
from .kinovea import read_kva
from .tables import check_units, read_kinovea_table, read_tracker_table
from .tracker import read_trk, read_trz

if TYPE_CHECKING:
    import os
    from collections.abc import Callable, Iterable

#: Formats whose files hold no settings (the config states units, fps, m_per_px).
TABLES = ("tracker_table", "kinovea_table")
DEFAULT_PATTERN = "{impact_id}_{camera}.{ext}"
BALLBAT_POINTS = tuple(dict.fromkeys(p for pts in POINTS.values() for p in pts))


@dataclass
class Imported:
    """Long track rows of every file, the camera settings found and what was left out."""

    columns: dict[str, np.ndarray]
    cameras: dict[str, dict]
    files: list[tuple[str, str, str]]  # (impact_id, camera, path)
    ignored: dict[str, list[str]] = field(default_factory=dict)  # path -> tracks left out

    def settings_yaml(self) -> dict:
        """Return the camera settings found, as ``ballbat import-tracks`` prints them and the workflow writes them."""
        out: dict = {"cameras": self.cameras, "files": len(self.files)}
        out["impacts"] = len({f[0] for f in self.files})
        out["rows"] = int(self.columns["frame"].size)
        if self.ignored:
            out["tracks_left_out"] = {p: sorted(t) for p, t in self.ignored.items()}
        return out


def pattern_regex(pattern: str, exts: Iterable[str]) -> re.Pattern:
    """Return the regular expression of a file-name pattern (``{impact_id}``, ``{camera}``, ``{ext}``)."""
    for key in ("{impact_id}", "{camera}", "{ext}"):
        if key != "{ext}" and key not in pattern:
            raise ValueError(f"pattern {pattern!r} lacks {key}")
        if pattern.count(key) > 1:
            raise ValueError(f"pattern {pattern!r} has {key} {pattern.count(key)} times (each field once)")
    out = re.escape(pattern)
    out = out.replace(re.escape("{impact_id}"), r"(?P<impact_id>.+?)")
    out = out.replace(re.escape("{camera}"), "(?P<camera>" + "|".join(CAMERAS) + ")")
    ext_alt = "|".join(re.escape(e.lstrip(".")) for e in sorted(set(exts)))
    out = out.replace(re.escape("{ext}"), f"(?P<ext>{ext_alt})")
    return re.compile(out + r"\Z", re.IGNORECASE)


def find_files(
    paths: Iterable[str | os.PathLike[str]], pattern: str = DEFAULT_PATTERN, fmt: str | None = None
) -> tuple[list[tuple[str, str, Path]], list[str]]:
    """Files of ``paths`` (files, or folders of them) as (impact_id, camera, path); problems listed.

    In a folder, files with a track-file extension must match the pattern; others (videos,
    notes) are left alone. A file named directly must match.
    """
    exts = tool_file_extensions(fmt)
    try:
        rx = pattern_regex(pattern, [*exts, *(e for f in FORMATS.values() for e in f)])
    except ValueError as exc:
        return [], [str(exc)]
    problems: list[str] = []
    found: dict[tuple[str, str], Path] = {}
    for p in map(Path, paths):
        if p.is_dir():
            cands = sorted(
                q for q in p.iterdir() if q.is_file() and q.suffix.lower() in exts and not q.name.startswith(".")
            )
            if not cands:
                problems.append(f"{p}: no {' or '.join(exts)} files in this folder")
        elif p.is_file():
            cands = [p]
        else:
            problems.append(f"{p}: no such file or folder")
            continue
        for q in cands:
            m = rx.match(q.name)
            if m is None:
                problems.append(
                    f"{q}: the name does not match the pattern {pattern!r} (camera: {' or '.join(CAMERAS)})"
                )
                continue
            if q.suffix.lower() not in exts:
                problems.append(
                    f"{q}: a {q.suffix} file is not read as {fmt or 'a tool file'} (expected {', '.join(exts)})"
                )
                continue
            key = (unicodedata.normalize("NFC", m["impact_id"]), m["camera"].lower())  # one form (NFC) of the id
            if key in found:
                problems.append(f"{q}: impact {key[0]!r}, camera {key[1]} already read from {found[key]}")
                continue
            found[key] = q
    return [(i, c, p) for (i, c), p in sorted(found.items())], problems


def check_points(points: object, where: str) -> list[str]:
    """Problems of a ``points`` map (ballbat point -> the tool's track name)."""
    if not isinstance(points, dict):
        return [
            f"{where}: missing (map ballbat's points to the tool's track names, "
            "e.g. {ball: ball, bat_tip: tip, dot_a: A, dot_b: B})"
        ]
    problems = [
        f"{where}.{k}: unknown point (known: {', '.join(BALLBAT_POINTS)})" for k in points if k not in BALLBAT_POINTS
    ]
    names = [str(v) for v in points.values()]
    problems += [
        f"{where}: track name {n!r} is given to several points"
        for n in sorted({n for n in names if names.count(n) > 1})
    ]
    return problems


def _read(path: Path, fmt: str, units: dict | None, cam: dict) -> FileTracks:
    if fmt == "tracker":
        return read_trz(path) if path.suffix.lower() == ".trz" else read_trk(path)
    if fmt == "kinovea":
        return read_kva(path)
    reader = read_tracker_table if fmt == "tracker_table" else read_kinovea_table
    return reader(path, units, float(cam["fps"]), float(cam["m_per_px"]))


def _far_frames(ft: FileTracks, iid: str, cam: str, points: dict) -> list[str]:
    """Name the marks of a file's tracks of ``points`` far outside the file's run of frames.

    Named before any array is sized by them (:func:`ballbat.tracks.checks.check_frame_runs`: a
    frame 999999999 is a typo).
    """
    from ..checks import check_frame_runs

    names = [str(points[p]) for p in POINTS[cam] if p in points and str(points[p]) in ft.tracks]
    have = [(n, ft.tracks[n][0]) for n in names if ft.tracks[n][0].size]
    if not have:
        return []
    fr = np.concatenate([f for _, f in have])
    labels = np.concatenate([np.full(f.size, f"track {n!r}") for n, f in have])
    return check_frame_runs(ft.path, np.full(fr.size, iid), np.full(fr.size, cam), fr, labels, column="")


def import_files(
    paths: Iterable[str | os.PathLike[str]],
    points: dict,
    *,
    pattern: str = DEFAULT_PATTERN,
    fmt: str | None = None,
    units: dict | None = None,
    cameras: dict | None = None,
    where: str = "tracks",
    reader: Callable[[list[tuple[Path, str, str, dict]]], list[FileTracks | FormatError]] | None = None,
) -> Imported:
    """Read a lab's tool files into long rows; camera settings from the files, checked against ``cameras``.

    Parameters
    ----------
    paths : iterable of path-like
        Files, or folders of files, one per impact and camera.
    points : dict
        ballbat point -> the tool's track name.
    pattern, fmt : str
        File-name pattern; format (None: from each file's extension, .trk/.trz/.kva).
    units : dict, optional
        ``time``, ``length``, ``y`` of a table format (required for tables).
    cameras : dict, optional
        Config camera settings (``fps``, ``m_per_px``, ...) per camera, to check and complete.
    where : str
        Config key of the block, for messages.
    reader : callable, optional
        Reader of the ``video`` format's clips: a list of (path, impact id, camera, camera config)
        in, each clip's FileTracks or FormatError out, in order
        (:func:`ballbat.video.importer.clip_reader`; the clips are tracked there).

    Raises
    ------
    FormatError
        Every problem of every file at once.
    """
    cameras = cameras or {}
    problems = _block_problems(points, fmt, units, cameras, where)
    if problems:
        raise FormatError(problems)
    files, problems = find_files(paths, pattern, fmt)
    read = _read_files(files, fmt, units, cameras, reader, problems)
    settings: dict[str, dict] = {}
    for cam in CAMERAS:
        these = [ft for _, c, ft in read if c == cam]
        settings[cam], sp = _camera_settings(cam, these, cameras.get(cam) or {}, f"{where}.cameras.{cam}")
        problems += sp
    cols: dict[str, list] = {k: [] for k in ("impact_id", "camera", "point", "frame", "x_px", "y_px")}
    ignored: dict[str, list[str]] = {}
    wanted = {str(v): k for k, v in points.items()}
    for iid, cam, ft in read:
        m = settings[cam].get("m_per_px")
        factor = ft.m_per_px / m if ft.m_per_px is not None and m else 1.0
        left = [n for n in ft.tracks if n not in wanted or wanted[n] not in POINTS[cam]]
        if left:
            ignored[ft.path] = left
        for p in POINTS[cam]:
            if p not in points:
                problems.append(
                    f"{ft.path}: no track name given for {p} ({cam} camera): add {p}: <the tool's name> to points"
                )
                continue
            name = str(points[p])
            if name not in ft.tracks or ft.tracks[name][0].size == 0:
                have = ", ".join(repr(n) for n in ft.tracks) or "none"
                why = "has no marks" if name in ft.tracks else "is not in the file"
                problems.append(f"{ft.path}: track {name!r} (ballbat's {p}, {cam} camera) {why} (tracks: {have})")
                continue
            fr, x, y = ft.tracks[name]
            if np.unique(fr).size != fr.size:
                u, n = np.unique(fr, return_counts=True)
                problems.append(
                    f"{ft.path}: track {name!r}: frame(s) {', '.join(map(str, u[n > 1][:5]))} marked twice "
                    f"({DUPLICATE_RULE})"
                )
                continue
            cols["impact_id"].append(np.full(fr.size, iid))
            cols["camera"].append(np.full(fr.size, cam))
            cols["point"].append(np.full(fr.size, p))
            cols["frame"].append(fr)
            cols["x_px"].append(x * factor if factor != 1.0 else x)
            cols["y_px"].append(y * factor if factor != 1.0 else y)
        problems += _far_frames(ft, iid, cam, points)
    if problems:
        raise FormatError(problems)
    out = {k: np.concatenate(v) if v else np.array([]) for k, v in cols.items()}
    return Imported(out, settings, [(i, c, ft.path) for i, c, ft in read], ignored)


def _read_files(files, fmt, units, cameras: dict, reader, problems: list[str]) -> list[tuple[str, str, FileTracks]]:
    """Read every (impact id, camera, path) of ``files``; each file's problems go to ``problems``."""
    read: list[tuple[str, str, FileTracks]] = []
    if fmt == "video":  # the clips tracked together (side by side: ClipReader)
        if reader is None:
            problems += [f"{p}: a clip, and no clip reader was given (ballbat.video.importer)" for _, _, p in files]
            return read
        got = reader([(path, iid, cam, cameras.get(cam) or {}) for iid, cam, path in files])
        for (iid, cam, _), ft in zip(files, got, strict=True):
            if isinstance(ft, FormatError):
                problems += ft.problems
            else:
                read.append((iid, cam, ft))
        return read
    for iid, cam, path in files:
        f = fmt or BY_EXTENSION[path.suffix.lower()]
        try:
            read.append((iid, cam, _read(path, f, units, cameras.get(cam) or {})))
        except FormatError as exc:
            problems += exc.problems
    return read


def _block_problems(points: dict, fmt: str | None, units: dict | None, cameras: dict, where: str) -> list[str]:
    """Problems of the block's settings for its files: points, format, units, what a table needs from the config."""
    problems = check_points(points, f"{where}.points")
    if fmt is not None and fmt not in FORMATS:
        problems.append(f"{where}.format: {fmt!r} is not one of {', '.join(FORMATS)}")
        fmt = None
    if units is not None and fmt not in TABLES:
        problems.append(
            f"{where}.units: given, but only a table (format tracker_table or kinovea_table) needs it: "
            "the tools' own files say their units"
        )
    if fmt == "video":
        for c in CAMERAS:
            if "m_per_px" not in (cameras.get(c) or {}):
                problems.append(
                    f"{where}.cameras.{c}.m_per_px: missing (a clip holds no scale, and the tracker sizes the ball "
                    "by it; no default)"
                )
    if fmt in TABLES:
        problems += check_units(units, f"{where}.units")
        for c in CAMERAS:
            for k in ("fps", "m_per_px"):
                if k not in (cameras.get(c) or {}):
                    problems.append(f"{where}.cameras.{c}.{k}: missing (a {fmt} holds no {k}; no default)")
    return problems


def _camera_settings(cam: str, files: list[FileTracks], config: dict, where: str) -> tuple[dict, list[str]]:
    """Return the frame rate and pixel scale of one camera: from its files, checked against the config."""
    problems: list[str] = []
    out: dict = {"files": len(files)}
    for key in ("fps", "m_per_px"):
        vals = [(ft.path, getattr(ft, key)) for ft in files if getattr(ft, key) is not None]
        given = config.get(key)
        if given is not None:
            bad = [(p, v) for p, v in vals if not close(v, float(given))]
            for p, v in bad[:5]:
                problems.append(
                    f"{where}.{key}: the config says {given:g} but {p} says {v:.6g} ({_src(files, p, key)})"
                )
            if len(bad) > 5:
                problems.append(f"{where}.{key}: ... and {len(bad) - 5} more {cam} files say otherwise than the config")
            out[key] = float(given)
            out[f"{key}_from"] = "config" + (f", agrees with {len(vals)} file(s)" if vals else "")
        elif vals:
            if key == "fps":
                ref = vals[0]
                bad = [(p, v) for p, v in vals if not close(v, ref[1])]
                for p, v in bad[:5]:
                    problems.append(
                        f"{p}: frame rate {v:.6g} fps differs from {ref[1]:.6g} fps of {ref[0]} (same {cam} camera)"
                    )
                out[key] = float(statistics.median(v for _, v in vals))
            else:
                out[key] = float(statistics.median(v for _, v in vals))
                lo, hi = min(v for _, v in vals), max(v for _, v in vals)
                if lo != hi:
                    out["m_per_px_range"] = [lo, hi]
            out[f"{key}_from"] = f"{len(vals)} file(s): {_src(files, vals[0][0], key)}"
            if len(vals) < len(files):
                miss = [ft.path for ft in files if getattr(ft, key) is None]
                problems.append(
                    f"{where}.{key}: {len(miss)} file(s) of the {cam} camera hold no {key} ({miss[0]}...) and the "
                    f"config gives none"
                )
        elif files:
            problems.append(
                f"{where}.{key}: missing: the {cam} camera's files do not hold it ({files[0].path}); "
                "give it in the config"
            )
    exposure, more = _exposure_setting(files, config, where)
    return {**out, **exposure}, problems + more


def _exposure_setting(files: list[FileTracks], config: dict, where: str) -> tuple[dict, list[str]]:
    """Return one camera's exposure time (us) from its files (clips), checked against the config's.

    The config's 0 (its default) is "not known": the files' value is taken. A value the config
    gives that a file contradicts (by more than 1 %, or 1 us) is a problem naming both. Files of
    one camera exposed differently: the longest is taken (the tip's fit keeps clear of the
    contact by a frame's exposure) and the spread is reported.
    """
    vals = [(ft.path, ft.exposure_s * 1e6) for ft in files if ft.exposure_s]
    given = float(config.get("exposure_us") or 0.0)
    if given > 0:
        bad = [(p, v) for p, v in vals if abs(v - given) > max(0.01 * given, 1.0)]
        problems = [
            f"{where}.exposure_us: the config says {given:g} us but {p} says {v:.4g} us "
            f"({_src(files, p, 'exposure_s')})"
            for p, v in bad[:5]
        ]
        agrees = f", agrees with {len(vals)} file(s)" if vals else ""
        return {"exposure_us": given, "exposure_us_from": "config" + agrees}, problems
    if not vals:
        return {}, []
    longest, shortest = max(v for _, v in vals), min(v for _, v in vals)
    out = {"exposure_us": longest, "exposure_us_from": f"{len(vals)} file(s): {_src(files, vals[0][0], 'exposure_s')}"}
    if shortest != longest:
        out["exposure_us_range"] = [shortest, longest]
    return out, []


def _src(files: list[FileTracks], path: str, key: str) -> str:
    ft = next(f for f in files if f.path == path)
    return ft.source.get(key, key)


def _table_spelling(imp: Imported, impacts: dict[str, str]) -> None:
    """Give the files' impact ids the impacts table's spelling where the two differ only in Unicode form.

    A file name can hold an accented id decomposed (NFD: macOS file systems) while the table holds it
    composed (NFC), or the other way: the two look the same and are matched as the same impact.
    """
    table = {unicodedata.normalize("NFC", k): k for k in impacts}
    rename = {iid: table[iid] for iid, _, _ in imp.files if iid in table and table[iid] != iid}
    if not rename:
        return
    imp.files = [(rename.get(iid, iid), cam, path) for iid, cam, path in imp.files]
    ids = imp.columns["impact_id"].astype(object)
    for old, new in rename.items():
        ids[ids == old] = new
    imp.columns["impact_id"] = ids.astype(str)


def ball_radii(irows: list, balls: dict | None) -> dict[str, float]:
    """Return each impact id's ball radius (m) of an impacts table's rows; an impact whose ball is unknown has none."""
    return {row.get("impact_id", ""): balls[row["ball"]].r for _, row in irows if balls and row.get("ball") in balls}


def import_block(
    cfg: dict, where: str, balls: dict | None = None, bats: dict | None = None, clip_reader: Callable | None = None
) -> tuple[Tracks, Imported]:
    """Read a dataset's validated ``tracks`` block that names a folder (``dir``): return (Tracks, Imported).

    The impacts file (``impacts``) gives each impact's bat and ball; every impact must have a
    file of each camera and every file an impact. Every problem is raised at once as an
    :class:`~ballbat.properties.InputError`. ``clip_reader(block, {impact id: ball radius m})``
    returns the reader of a ``format: video`` block's clips
    (:func:`ballbat.video.importer.clip_reader`).
    """
    from ...properties import InputError
    from ..io import _assemble, read_impacts

    ipath = Path(cfg["impacts"])
    impacts, irows, problems = read_impacts(ipath, balls, bats)
    impacts = impacts or {}
    if "video" in cfg and cfg.get("format") != "video":
        problems.append(f"{where}.video: given, but only a folder of clips (format: video) is tracked")
    reader = None
    if cfg.get("format") == "video" and clip_reader is not None:
        reader = clip_reader(cfg, ball_radii(irows, balls))
    try:
        imp = import_files(
            [cfg["dir"]],
            cfg.get("points") or ({p: p for p in BALLBAT_POINTS} if cfg.get("format") == "video" else None),
            pattern=cfg["pattern"],
            fmt=cfg.get("format"),
            units=cfg.get("units"),
            cameras=cfg.get("cameras"),
            where=where,
            reader=reader,
        )
    except FormatError as exc:
        raise InputError(problems + exc.problems) from None
    _table_spelling(imp, impacts)
    have: dict[str, set] = {}
    for iid, cam, path in imp.files:
        have.setdefault(iid, set()).add(cam)
        if impacts and iid not in impacts:
            problems.append(f"{path}: impact {iid!r} is not in {ipath} (add a row impact_id,bat,ball)")
    for iid, label in impacts.items():
        miss = [c for c in CAMERAS if c not in have.get(iid, set())]
        if miss:
            names = " and ".join(cfg["pattern"].replace("{impact_id}", iid).replace("{camera}", c) for c in miss)
            problems.append(
                f"{ipath}: {label}: impact {iid!r} has no file of the {' and '.join(miss)} camera "
                f"in {cfg['dir']} ({names})"
            )
    if problems:
        raise InputError(problems)
    return _assemble(imp.columns, irows, None, str(cfg["dir"])), imp
