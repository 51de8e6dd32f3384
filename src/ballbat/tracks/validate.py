"""Checks of a lab's tracks, impacts and camera settings: every problem at once.

Each message names the file (or config key), the row (CSV line number, header = line 1;
NetCDF index) and the column, and says what is wrong, in the style of
:mod:`ballbat.ingest`. The functions return lists of problems; :mod:`.io` raises them
together as one :class:`~ballbat.properties.InputError`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..properties import EXTRA, cell_number, check_impact_id, header_problems, table_keys
from .checks import SCALE_ERR_MAX
from .data import CAMERAS, POINTS
from .formats import DUPLICATE_RULE

if TYPE_CHECKING:
    import os

#: Columns of a tracks file (long format, one row per tracked point per frame).
TRACK_COLUMNS = ("impact_id", "camera", "point", "frame", "x_px", "y_px")
#: Columns of an impacts file.
IMPACT_COLUMNS = ("impact_id", "bat", "ball")
#: Keys of a camera's settings and of the rig.
CAMERA_KEYS = {"fps", "m_per_px", "mirror", "m_per_px_err", "fps_err", "exposure_us"}
CAMERA_REQUIRED = ("fps", "m_per_px", "mirror")
RIG_KEYS = ("pivot_to_tip_in", "pivot_to_impact_in")
#: Optional standard uncertainties of the rig's lengths (in; systematics, docs/tracks.md).
RIG_ERR_KEYS = ("pivot_to_tip_err_in", "pivot_to_impact_err_in")


def check_header(path: str | os.PathLike[str], header: list[str], required: tuple[str, ...]) -> list[str]:
    """Missing, unknown and repeated columns (:func:`ballbat.properties.header_problems`)."""
    return header_problems(path, header, required)


def check_impact_rows(
    path: str | os.PathLike[str], rows: list, balls: dict | None = None, bats: dict | None = None
) -> tuple[dict[str, str], list[str]]:
    """Impact rows: ids unique and present, bat and ball given (and in the tables when known).

    Returns ``({impact_id: row label}, problems)``.
    """
    problems: list[str] = []
    seen: dict[str, str] = {}
    if not rows:
        problems.append(f"{path}: no impacts (only a header)")
    for label, row in rows:
        at = f"{path}: {label}"
        if EXTRA in row:
            problems.append(f"{at}: {row[EXTRA]} more cell(s) than the header has columns")
        check_impact_id(row.get("impact_id", ""), at, label, seen, problems)
        table_keys(row, at, balls, bats, problems)
    return seen, problems


def check_track_rows(
    path: str | os.PathLike[str],
    rows: list,
    impacts: dict[str, str] | None,
    impacts_path: str | os.PathLike[str] | None = None,
) -> tuple[dict, list[str]]:
    """Track rows: known camera and point names, whole frame numbers, finite pixels, no frame twice.

    Parameters
    ----------
    path : path-like
        The tracks file (for messages).
    rows : list of (label, {column: text})
        Its rows.
    impacts : dict or None
        Impact ids of the impacts file (id -> row label); None skips that check.
    impacts_path : path-like, optional
        The impacts file (for messages).

    Returns
    -------
    (columns, problems)
        ``columns`` maps each column to a list of parsed values, plus ``label``.
    """
    problems: list[str] = []
    out: dict[str, list] = {c: [] for c in (*TRACK_COLUMNS, "label")}
    seen: dict[tuple, str] = {}
    unknown_impacts: dict[str, list[str]] = {}
    if not rows:
        problems.append(f"{path}: no tracks (only a header)")
    for label, row in rows:
        at = f"{path}: {label}"
        bad = False
        if EXTRA in row:
            problems.append(f"{at}: {row[EXTRA]} more cell(s) than the header has columns")
        iid = row.get("impact_id", "")
        if not iid:
            problems.append(f"{at}, column impact_id: empty")
            bad = True
        elif impacts is not None and iid not in impacts:
            unknown_impacts.setdefault(iid, []).append(label)
            bad = True
        cam = row.get("camera", "")
        if cam not in POINTS:
            problems.append(
                f"{at}, column camera: "
                + (f"unknown camera {cam!r}" if cam else "empty")
                + f" (known: {', '.join(CAMERAS)})"
            )
            bad = True
        point = row.get("point", "")
        if cam in POINTS and point not in POINTS[cam]:
            problems.append(
                f"{at}, column point: "
                + (f"unknown point {point!r} for the {cam} camera" if point else "empty")
                + f" (known: {', '.join(POINTS[cam])})"
            )
            bad = True
        n0 = len(problems)
        frame = cell_number(row.get("frame", ""), f"{at}, column frame", problems, integer=True)
        x = cell_number(row.get("x_px", ""), f"{at}, column x_px", problems)
        y = cell_number(row.get("y_px", ""), f"{at}, column y_px", problems)
        bad = bad or len(problems) > n0
        if bad:
            continue
        key = (iid, cam, point, int(frame))
        if key in seen:
            problems.append(
                f"{at}, column frame: frame {int(frame)} of {point} in the {cam} camera of impact {iid!r} "
                f"appears twice (also {seen[key]}); {DUPLICATE_RULE}"
            )
            continue
        seen[key] = label
        for c, v in zip((*TRACK_COLUMNS, "label"), (iid, cam, point, int(frame), x, y, label), strict=True):
            out[c].append(v)
    for iid, labels in unknown_impacts.items():
        where = ", ".join(labels[:3]) + (f" and {len(labels) - 3} more" if len(labels) > 3 else "")
        problems.append(
            f"{path}: {where}, column impact_id: impact {iid!r} is not in {impacts_path} (add a row impact_id,bat,ball)"
        )
    if impacts is not None:
        problems += _missing_tracks(path, seen, impacts, impacts_path, unknown_impacts)
    return out, problems


def _missing_tracks(path, seen: dict, impacts: dict, impacts_path, unknown_impacts: dict) -> list[str]:
    """Name each impact of the impacts file without tracks, or without a camera or a point of one."""
    problems = []
    have: dict[str, set] = {}
    for iid, cam, point in {(k[0], k[1], k[2]) for k in seen}:
        have.setdefault(iid, set()).add((cam, point))
    for iid, label in impacts.items():
        got = have.get(iid)
        if not got and iid not in unknown_impacts:
            problems.append(f"{impacts_path}: {label}: impact {iid!r} has no tracks in {path}")
            continue
        for cam in CAMERAS:
            pts = [p for p in POINTS[cam] if (cam, p) in got]
            if not pts:
                problems.append(
                    f"{path}: impact {iid!r} ({impacts_path}: {label}): the {cam} camera is missing "
                    f"(no rows with camera {cam}; each impact needs both cameras)"
                )
            elif len(pts) < len(POINTS[cam]):
                miss = [p for p in POINTS[cam] if p not in pts]
                problems.append(
                    f"{path}: impact {iid!r} ({impacts_path}: {label}): the {cam} camera has no rows of "
                    f"point(s) {', '.join(miss)}"
                )
    return problems


def check_cameras(cfg: object, where: str) -> list[str]:
    """Camera settings (``cameras``) and rig (``rig``) of a tracked dataset's config block."""
    problems: list[str] = []
    cams = cfg.get("cameras") if isinstance(cfg, dict) else None
    if not isinstance(cams, dict):
        return [f"{where}.cameras: missing (give swing and spin: fps, m_per_px, mirror)"]
    for name in cams:
        if name not in POINTS:
            problems.append(f"{where}.cameras.{name}: unknown camera (known: {', '.join(CAMERAS)})")
    for name in CAMERAS:
        c = cams.get(name)
        at = f"{where}.cameras.{name}"
        if c is None:
            problems.append(f"{at}: camera missing (give fps, m_per_px, mirror)")
        elif not isinstance(c, dict):
            problems.append(f"{at}: expected a mapping of fps, m_per_px, mirror")
        else:
            problems += _camera_problems(c, at)
    rig = cfg.get("rig")
    if not isinstance(rig, dict):
        problems.append(f"{where}.rig: missing (give {', '.join(RIG_KEYS)})")
        return problems
    return problems + _rig_problems(rig, where)


def _camera_problems(c: dict, at: str) -> list[str]:
    """Problems of one camera's settings (``at``: its config key)."""
    problems: list[str] = []
    for k in CAMERA_REQUIRED:
        if k not in c:
            problems.append(f"{at}.{k}: missing")
    for k in c:
        if k not in CAMERA_KEYS:
            problems.append(f"{at}.{k}: unknown setting (known: {', '.join(sorted(CAMERA_KEYS))})")
    for k in ("fps", "m_per_px"):
        if k in c and not (_is_number(c[k]) and c[k] > 0):
            problems.append(f"{at}.{k}: {c[k]!r} must be a positive number")
    if "m_per_px_err" in c and not (_is_number(c["m_per_px_err"]) and c["m_per_px_err"] >= 0):
        problems.append(f"{at}.m_per_px_err: {c['m_per_px_err']!r} must be a number >= 0 (relative uncertainty)")
    elif "m_per_px_err" in c and c["m_per_px_err"] >= SCALE_ERR_MAX:
        problems.append(
            f"{at}.m_per_px_err: {c['m_per_px_err']!r} is a relative uncertainty ({100 * c['m_per_px_err']:g} %): "
            f"a pixel scale known no better than {100 * SCALE_ERR_MAX:g} % shifts e_x by about as much as e_x "
            f"varies between bats. For {c['m_per_px_err']!r} % write {c['m_per_px_err'] / 100:g}"
        )
    if "fps_err" in c and not (_is_number(c["fps_err"]) and 0 <= c["fps_err"] < SCALE_ERR_MAX):
        problems.append(
            f"{at}.fps_err: {c['fps_err']!r} must be a relative uncertainty >= 0 and below {SCALE_ERR_MAX:g} "
            "(0.001 for 0.1 %)"
        )
    if "mirror" in c and not isinstance(c["mirror"], bool):
        problems.append(f"{at}.mirror: {c['mirror']!r} must be true or false")
    return problems + _exposure_problems(c, at)


def _exposure_problems(c: dict, at: str) -> list[str]:
    """Problems of a camera's exposure time (us): a number >= 0, shorter than the time between frames."""
    if "exposure_us" not in c:
        return []
    e = c["exposure_us"]
    if not (_is_number(e) and e >= 0):
        return [f"{at}.exposure_us: {e!r} must be a number >= 0 (microseconds; 0: not known)"]
    if _is_number(c.get("fps")) and c["fps"] > 0 and e > 1e6 / c["fps"] * (1 + 1e-9):
        return [
            f"{at}.exposure_us: {e:g} us is longer than the {1e6 / c['fps']:.4g} us between frames at "
            f"{c['fps']:g} fps: a frame cannot be exposed for longer (microseconds: 1/20000 s is 50)"
        ]
    return []


def _rig_problems(rig: dict, where: str) -> list[str]:
    """Problems of the rig's lengths and their uncertainties (inches)."""
    problems: list[str] = []
    for k in RIG_KEYS:
        if k not in rig:
            problems.append(f"{where}.rig.{k}: missing")
        elif not (_is_number(rig[k]) and rig[k] > 0):
            problems.append(f"{where}.rig.{k}: {rig[k]!r} must be a positive number (inches)")
    for k in rig:
        if k not in RIG_KEYS + RIG_ERR_KEYS:
            problems.append(f"{where}.rig.{k}: unknown setting (known: {', '.join(RIG_KEYS + RIG_ERR_KEYS)})")
    for k, length in zip(RIG_ERR_KEYS, RIG_KEYS, strict=True):
        if k in rig and not (_is_number(rig[k]) and rig[k] >= 0):
            problems.append(f"{where}.rig.{k}: {rig[k]!r} must be a number >= 0 (standard uncertainty, inches)")
        elif k in rig and _is_number(rig.get(length)) and rig[k] >= SCALE_ERR_MAX * rig[length]:
            problems.append(
                f"{where}.rig.{k}: {rig[k]!r} in is {100 * rig[k] / rig[length]:.3g} % of {length} {rig[length]}: "
                f"give a standard uncertainty below {100 * SCALE_ERR_MAX:g} % of the length (inches)"
            )
    if all(_is_number(rig.get(k)) for k in RIG_KEYS) and rig["pivot_to_impact_in"] > rig["pivot_to_tip_in"]:
        problems.append(
            f"{where}.rig: pivot_to_impact_in {rig['pivot_to_impact_in']} is beyond pivot_to_tip_in "
            f"{rig['pivot_to_tip_in']} (the impact point lies between the pivot and the tip)"
        )
    return problems


def _is_number(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
