"""What the contact sheet of a dataset's clips shows: a few frames of a few impacts, with the points tracked in them.

:func:`sheet_rows` streams each chosen clip once and keeps only the frames it shows (memory:
those frames); :func:`ballbat.plotting_tracks.contact_sheet` draws them.
"""

from __future__ import annotations

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
