"""Stage import_clips' ``imported_quality.nc``: the tracker's quality of every point of a dataset's clips.

Beside ``imported_tracks.nc`` (:func:`.render.tracks_dataset`), for a dataset whose tracks come
from clips (docs/video.md, "In the workflow"): one row per point the tracker gave or left out
(dimension ``row``), as :func:`ballbat.video.track.found_columns` lays out its quality table.
A point found has its position, the ball's edge-fit RMS residual (NaN for the dots' and the
marker's centroids) and its contrast; a point left out has no position (NaN) and its reason.
:func:`quality_columns` reads the file back into those columns (the QA figure's input,
:func:`ballbat.video.qa.camera_quality`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import xarray as xr

from ..pipeline.products import Var, build_dataset

#: The variables of ``imported_quality.nc`` (one per column of the tracker's quality table).
QUALITY_TABLE = {
    "impact_id": Var(("row",), None, "impact of the row (its clip: impact and camera)"),
    "camera": Var(("row",), None, "camera of the row (swing: Camera 1, spin: Camera 2)"),
    "point": Var(("row",), None, "point (ball, dot_a, dot_b, bat_tip; dot: a spot on the ball's limb, left out)"),
    "frame": Var(("row",), "1", "frame number of the clip (the file's, counted from the trigger, where it has them)"),
    "x_px": Var(("row",), "1", "image x of the point (pixels, to the right; NaN: left out)"),
    "y_px": Var(("row",), "1", "image y of the point (pixels, downward; NaN: left out)"),
    "residual_px": Var(
        ("row",), "1", "RMS residual of the ball's edge about its fitted circle (pixels; NaN: a centroid, or left out)"
    ),
    "contrast": Var(
        ("row",),
        "1",
        "contrast of the point (grey levels of its clip: the ball's median edge step, the dots' darkness, "
        "the marker's brightness above its surround; NaN: left out)",
    ),
    "left_out": Var(("row",), None, "why the tracker left the point out (empty: found)"),
}


def quality_dataset(columns: Mapping[str, np.ndarray]) -> xr.Dataset:
    """Return the tracker's quality table (the columns of :func:`ballbat.video.track.found_columns`) as NetCDF.

    Attributes: the clips, the rows, the points found and those left out.
    """
    values = {k: np.asarray(columns[k]) for k in QUALITY_TABLE}
    for k in ("impact_id", "camera", "point", "left_out"):
        values[k] = values[k].astype(str)
    values["frame"] = values["frame"].astype(np.int64)
    found = values["left_out"] == ""
    clips = {(i, c) for i, c in zip(values["impact_id"], values["camera"], strict=True)}
    attrs = {"n_clips": len(clips), "n_rows": int(found.size), "n_found": int(found.sum())}
    attrs["n_left_out"] = int((~found).sum())
    return build_dataset(QUALITY_TABLE, values, attrs=attrs)


def quality_columns(ds: xr.Dataset) -> dict[str, np.ndarray]:
    """Return the quality table's columns of ``imported_quality.nc`` (text as str, a reason "" where found)."""
    missing = [k for k in QUALITY_TABLE if k not in ds]
    if missing:
        raise KeyError(f"not a quality table of the tracker: no {', '.join(missing)}")
    out = {k: ds[k].values for k in QUALITY_TABLE}
    for k in ("impact_id", "camera", "point", "left_out"):
        out[k] = np.array(["" if v is None else str(v) for v in out[k]], dtype=object)
    return out
