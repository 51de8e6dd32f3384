"""What the QA figures of a dataset's clips show (docs/video.md, "In the workflow").

* The contact sheet: a few frames of a few impacts, with the points tracked in them.
  :func:`sheet_rows` streams each chosen clip once and keeps only the frames it shows (memory:
  those frames); :func:`ballbat.plotting_tracks.contact_sheet` draws them.
* The tracking quality per camera: :func:`camera_quality` sums the tracker's quality table
  (``imported_quality.nc``) per camera: the ball's edge-fit residuals, each point type's
  contrasts, and the points found and left out per reason;
  :func:`ballbat.plotting_tracks.quality_figure` draws them.
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .io import open_clip

if TYPE_CHECKING:
    from ..tracks.data import TrackBlocks, Tracks


@dataclass
class SheetRow:
    """One clip's row of the sheet: its label and the frames shown, each with the points tracked in it."""

    label: str
    frames: list[tuple[int, np.ndarray, dict[str, tuple[float, float]]]]  # (frame number, image, point -> x, y)


def _tracked(tracks: Tracks | TrackBlocks, i: int, camera: str) -> dict[int, dict[str, tuple[float, float]]]:
    """Frame number -> the points tracked in it, for impact ``i`` of ``tracks`` in ``camera``."""
    block, i = tracks.locate(i)
    ct = block.cameras[camera]
    frames = ct.frames()[i]
    out: dict[int, dict[str, tuple[float, float]]] = {}
    for p in ct.x:
        ok = np.isfinite(ct.x[p][i])
        for f, x, y in zip(frames[ok], ct.x[p][i][ok], ct.y[p][i][ok], strict=True):
            out.setdefault(int(f), {})[p] = (float(x), float(y))
    return out


def block_clips(block: dict) -> dict[tuple[str, str], Path]:
    """Return the clips of a ``format: video`` block's folder by (impact id, camera), found as the import finds them."""
    from ..tracks.formats.layout import find_files

    files, _ = find_files([block["dir"]], block["pattern"], "video")
    return {(iid, cam): path for iid, cam, path in files}


def sheet_rows(
    clips: dict[tuple[str, str], Path], tracks: Tracks | TrackBlocks, impacts: list[int], n: int = 5
) -> list[SheetRow]:
    """Return the sheet's rows: for each of ``impacts`` (indices into ``tracks``), each camera's clip, ``n`` frames.

    The frames are spread evenly over the clip's frames in which a point was tracked; each
    comes with the points tracked in it (none drawn where the tracker left a point out).
    """
    rows = []
    for i in impacts:
        iid = str(tracks.impact_id[i])
        for cam in ("swing", "spin"):
            path = clips.get((iid, cam))
            if path is None:
                continue
            found = _tracked(tracks, i, cam)
            clip = open_clip(path)
            numbers = clip.info.frame_numbers
            have = sorted(found) or [int(numbers[0]) if numbers is not None else 0]
            want = {have[round(k)] for k in np.linspace(0, len(have) - 1, min(n, len(have)))}
            shown = []
            for k, _, img in clip.frames():
                f = int(numbers[k]) if numbers is not None and k < numbers.size else k
                if f in want:
                    shown.append((f, img, found.get(f, {})))
            rows.append(SheetRow(f"{iid} {cam}", shown))
    return rows


#: The point types of the quality figure: the tracker's points (and ``dot``, a spot on the limb) by type.
POINT_TYPES = {"ball": "ball", "dot_a": "dots", "dot_b": "dots", "dot": "dots", "bat_tip": "bat_tip"}
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?")
_ASIDE = re.compile(r"\s*\([^)]*\)")


def reason_kind(reason: str) -> str:
    """Return the kind of a reason a point was left out: without its numbers (``n``), asides in brackets, positions.

    "ball edge not round (residual 0.61 px; ...)" -> "ball edge not round"; "2 balls found" -> "n balls found".
    """
    kind = _NUMBER.sub("n", _ASIDE.sub("", reason)).strip()
    return kind.replace(" at n, n ", " ")  # "spot at 312.4, 190.0 on the limb" -> "spot on the limb"


@dataclass
class CameraQuality:
    """One camera's tracking quality, summed over its clips."""

    camera: str
    clips: int  # clips (impacts) of the camera in the table
    frames: int  # frames tracked (each frame of a clip has a row of its ball, found or left out)
    residual_px: np.ndarray  # the ball's edge-fit RMS residual of each ball found (px)
    contrast: dict[str, np.ndarray]  # point type -> the contrast of each point of it found (grey levels)
    counts: dict[tuple[str, str], int]  # (point type, "found" or the kind of reason left out) -> rows

    @property
    def found(self) -> int:
        """Return the points found."""
        return sum(n for (_, what), n in self.counts.items() if what == "found")

    @property
    def left_out(self) -> int:
        """Return the points left out (a spot on the limb counted as one)."""
        return sum(n for (_, what), n in self.counts.items() if what != "found")


def camera_quality(columns: Mapping[str, np.ndarray]) -> list[CameraQuality]:
    """Return each camera's tracking quality from the tracker's quality table (swing, then spin; only those in it).

    ``columns``: :func:`ballbat.video.track.found_columns`' quality table (``imported_quality.nc`` read back by
    :func:`ballbat.stages.quality.quality_columns`).
    """
    cam = np.asarray(columns["camera"]).astype(str)
    out = []
    for c in [c for c in ("swing", "spin") if c in set(cam)] + sorted(set(cam) - {"swing", "spin"}):
        sel = cam == c
        iid = np.asarray(columns["impact_id"]).astype(str)[sel]
        frame = np.asarray(columns["frame"])[sel]
        point = np.array([POINT_TYPES.get(p, p) for p in np.asarray(columns["point"]).astype(str)[sel]])
        why = np.asarray(columns["left_out"]).astype(str)[sel]
        found = why == ""
        resid = np.asarray(columns["residual_px"], dtype=float)[sel]
        contrast = np.asarray(columns["contrast"], dtype=float)[sel]
        types = [t for t in dict.fromkeys(POINT_TYPES.values()) if t in set(point)]
        types += sorted(set(point) - set(types))
        kinds = Counter((p, "found" if ok else reason_kind(w)) for p, ok, w in zip(point, found, why, strict=True))
        out.append(
            CameraQuality(
                c,
                clips=len(set(iid)),
                frames=len(set(zip(iid, frame, strict=True))),
                residual_px=resid[found & (point == "ball") & np.isfinite(resid)],
                contrast={t: contrast[found & (point == t) & np.isfinite(contrast)] for t in types},
                counts={
                    k: kinds[k]
                    for k in sorted(kinds, key=lambda k: (types.index(k[0]), k[1] != "found", -kinds[k], k[1]))
                },
            )
        )
    return out
