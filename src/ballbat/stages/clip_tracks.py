"""Stage track_clips: ``results/{dataset}/clip_tracks/batch_{k}.nc``, one batch of a dataset's clips tracked.

A dataset whose tracks come from clips is tracked one job per batch of clips (the plan:
:mod:`ballbat.video.plan`), each job one thread, side by side. A batch file holds the tracker's
quality table of its clips (:data:`~ballbat.stages.quality.QUALITY_TABLE`, dimension ``row``:
every point found, with its position, and every point left out, with its reason) and what each
clip's file said of itself (dimension ``clip``: its path, its frame rate and where that came
from). The points found are the clip's tracks, so the file holds them once.

:class:`GatheredClips` is the import's clip reader of a run with batches: it reads each clip's
tracks and quality back from the batch files (:func:`batch_clips`) instead of tracking it, so
that ``import_clips`` writes the same ``imported_tracks.nc`` and ``imported_quality.nc`` as
tracking every clip in one job did (``tests/workflow/test_video.py``).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..pipeline.products import Var, build_dataset
from ..tracks.data import POINTS
from ..tracks.formats import FileTracks, FormatError
from .quality import QUALITY_TABLE, quality_columns

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    import xarray as xr

    from ..video.plan import Clip

__all__ = ["BATCH_TABLE", "GatheredClips", "batch_clips", "run", "track_batch"]

#: The variables of a batch file: the quality table of its clips, and one row per clip.
BATCH_TABLE = {
    **QUALITY_TABLE,
    "clip_impact_id": Var(("clip",), None, "impact of the clip"),
    "clip_camera": Var(("clip",), None, "camera of the clip (swing: Camera 1, spin: Camera 2)"),
    "clip_path": Var(("clip",), None, "the clip's file, as the import finds it in the dataset's folder"),
    "clip_fps": Var(("clip",), "Hz", "frame rate the clip's file holds (NaN: none, the config must give it)"),
    "clip_fps_source": Var(("clip",), None, "where in the clip's file its frame rate was read"),
    "clip_exposure": Var(("clip",), "s", "exposure time of a frame the clip's file holds (NaN: none)"),
    "clip_exposure_source": Var(("clip",), None, "where in the clip's file its exposure time was read"),
}


def run(tracker: dict, balls: dict) -> xr.Dataset:
    """Track the batch the rule's ``tracker`` params name; return the batch file's contents.

    ``tracker``: ``clips`` ([impact id, camera, path] each), ``m_per_px`` (per camera), ``video``
    (the markers' sizes), ``impacts`` (the impacts table, for each impact's ball; its own
    problems are the import's to name) and ``where`` (the config key, for messages). ``balls``: the
    balls table (:func:`ballbat.properties.load_balls`).
    """
    from ..properties import InputError
    from ..tracks.formats.layout import ball_radii
    from ..tracks.io import read_impacts

    missing = [c for c, m in tracker["m_per_px"].items() if m is None]
    if missing:
        raise InputError(
            [
                f"{tracker['where']}.cameras.{c}.m_per_px: missing (a clip holds no scale, and the tracker sizes the "
                "ball by it; no default)"
                for c in missing
            ]
        )
    _, irows, _ = read_impacts(Path(tracker["impacts"]), balls, None)
    clips = [(str(i), str(c), str(p)) for i, c, p in tracker["clips"]]
    return track_batch(clips, tracker["m_per_px"], tracker["video"], ball_radii(irows, balls))


def track_batch(clips: list[Clip], m_per_px: dict[str, float], video: dict, radius: dict[str, float]) -> xr.Dataset:
    """Track one batch of clips, one after another; return the batch file's contents.

    ``clips``: (impact id, camera, path) each; ``m_per_px``: each camera's scale; ``video``: the
    markers' sizes (``dot_radius_mm``, ``marker_radius_mm``); ``radius``: each impact's ball
    radius (m). Every problem of every clip (naming the file and the frame) is raised at once as
    a :class:`FormatError`, and nothing is returned.
    """
    from ..video.importer import ClipReader

    reader = ClipReader({"video": video}, radius)
    items = [(Path(p), iid, cam, {"m_per_px": m_per_px[cam]}) for iid, cam, p in clips]
    got = reader(items)
    problems = [q for g in got if isinstance(g, FormatError) for q in g.problems]
    if problems:
        raise FormatError(problems)
    return batch_dataset(clips, got, reader.quality)


def batch_dataset(clips: list[Clip], tracks: list[FileTracks], quality: list[dict[str, np.ndarray]]) -> xr.Dataset:
    """Return a batch file's contents: the clips' quality tables, one after another, and each clip's settings."""
    from ..video.track import joined_quality

    joined = joined_quality(quality)
    values = {k: joined[k] for k in QUALITY_TABLE}
    for k in ("impact_id", "camera", "point", "left_out"):
        values[k] = values[k].astype(str)
    values["frame"] = values["frame"].astype(np.int64)
    values["clip_impact_id"] = np.array([c[0] for c in clips], dtype=str)
    values["clip_camera"] = np.array([c[1] for c in clips], dtype=str)
    values["clip_path"] = np.array([ft.path for ft in tracks], dtype=str)
    values["clip_fps"] = np.array([np.nan if ft.fps is None else ft.fps for ft in tracks], dtype=float)
    values["clip_fps_source"] = np.array([ft.source.get("fps", "") for ft in tracks], dtype=str)
    values["clip_exposure"] = np.array([np.nan if ft.exposure_s is None else ft.exposure_s for ft in tracks], float)
    values["clip_exposure_source"] = np.array([ft.source.get("exposure_s", "") for ft in tracks], dtype=str)
    attrs = {"n_clips": len(clips), "n_found": int((values["left_out"] == "").sum())}
    return build_dataset(BATCH_TABLE, values, attrs=attrs)


def batch_clips(ds: xr.Dataset) -> dict[str, tuple[FileTracks, dict[str, np.ndarray]]]:
    """Read a batch file back: each clip's path -> (its tracks, as tracking gave them; its quality table's columns)."""
    q = quality_columns(ds)
    found = q["left_out"] == ""
    out = {}
    for k in range(ds.sizes["clip"]):
        iid, cam = str(ds["clip_impact_id"].values[k]), str(ds["clip_camera"].values[k])
        path, fps = str(ds["clip_path"].values[k]), float(ds["clip_fps"].values[k])
        mine = (q["impact_id"] == iid) & (q["camera"] == cam)
        tracks = {}
        for p in POINTS[cam]:
            sel = mine & found & (q["point"] == p)
            tracks[p] = (q["frame"][sel].astype(np.int64), q["x_px"][sel].astype(float), q["y_px"][sel].astype(float))
        source = {"fps": str(ds["clip_fps_source"].values[k]), "exposure_s": str(ds["clip_exposure_source"].values[k])}
        exposure = float(ds["clip_exposure"].values[k])
        ft = FileTracks(
            path,
            tracks,
            fps=None if np.isnan(fps) else fps,
            source=source,
            exposure_s=None if np.isnan(exposure) else exposure,
        )
        out[path] = (ft, {c: v[mine] for c, v in q.items()})
    return out


class GatheredClips:
    """The import's clip reader of a run with batches: each clip's tracks read from the batch files, not tracked.

    For :func:`~ballbat.tracks.formats.layout.import_block` (``clip_reader``), as
    :class:`ballbat.video.importer.ClipImport`: :meth:`quality` gives the quality table of every
    clip read, in the import's order; :meth:`unread` the batches' clips the import did not find.
    """

    def __init__(self, batches: Iterable[xr.Dataset]) -> None:
        self.clips: dict[str, tuple[FileTracks, dict[str, np.ndarray]]] = {}
        for ds in batches:
            self.clips.update(batch_clips(ds))
        self.tables: list[dict[str, np.ndarray]] = []
        self.read: set[str] = set()

    def __call__(self, block: dict, ball_radius_m: dict[str, float]) -> Callable:
        """Return the reader of a block's clips: (path, impact id, camera, camera config) each -> FileTracks."""

        def read(items: list[tuple[Path, str, str, dict]]) -> list[FileTracks | FormatError]:
            out: list[FileTracks | FormatError] = []
            for path, iid, _, _ in items:
                if iid not in ball_radius_m:
                    out.append(FormatError([f"{path}: impact {iid!r} has no ball in the impacts table"]))
                elif str(path) not in self.clips:
                    why = "no batch of this run tracked it (a clip added since the run started? run again)"
                    out.append(FormatError([f"{path}: {why}"]))
                else:
                    ft, table = self.clips[str(path)]
                    self.read.add(str(path))
                    self.tables.append(table)
                    out.append(ft)
            return out

        return read

    def quality(self) -> dict[str, np.ndarray]:
        """Return the quality table of every clip read, clip after clip (as :meth:`ClipImport.quality`)."""
        from ..video.track import joined_quality

        return joined_quality(self.tables)

    def unread(self) -> list[str]:
        """Return the clips the batches hold that the import did not read (gone from the folder since)."""
        return sorted(set(self.clips) - self.read)
