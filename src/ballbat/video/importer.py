"""High-speed clips as a dataset's tracking files: each clip tracked into the tracks one tool file holds.

A dataset's ``tracks`` block with ``format: video`` names a folder of clips, one per impact and
camera (``{impact_id}_{camera}.{ext}``: ``.cine``, ``.cihx``/``.cih``, ``.tif``/``.tiff``,
``.mkv``, ``.mp4``, ``.avi``, ``.mov``), as it names a folder of Tracker or Kinovea files. Each
clip is read and tracked (:func:`ballbat.video.track.track_clip`) into a
:class:`~ballbat.tracks.formats.FileTracks`: its points under ballbat's own names, the frame
rate the file holds (checked against the config's by the import, as a Tracker file's is).
The tracker's sizes come from the lab's scale: the ball's radius is the balls table's radius
over the camera's ``m_per_px``, the dots' and the tip marker's from ``video.dot_radius_mm`` and
``video.marker_radius_mm``. The clip then checks the scale: the ball's fitted radius (median of
its frames) more than :data:`RADIUS_LIMIT` from the expected one is an error naming the clip,
both radii and the ``m_per_px`` the clip implies.

The tracker's quality of every point (each point found with its edge-fit residual and
contrast, each left out with its reason: :func:`ballbat.video.track.found_columns`) is kept
by the reader, clip by clip (:attr:`ClipReader.quality`); :class:`ClipImport` hands it to the
import's rule, which writes it beside the tracks (:mod:`ballbat.stages.quality`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..tracks.data import POINTS
from ..tracks.formats import FileTracks, FormatError
from .clip import VideoError
from .io import open_clip
from .track import Found, TrackOptions, found_columns, joined_quality, require_ball, track_clip

#: Largest relative difference of the ball's measured radius from the one the config implies
#: (Table I's radius / m_per_px). The fitted radius is within 1 % of the truth on rendered clips
#: (lossless and H.264 at CRF 18; docs/video.md); a real ball's diameter is within about 1 % of
#: its type's. More than 5 % is an m_per_px typed wrong, or another ball.
RADIUS_LIMIT = 0.05


def clip_tracks(path: Path, camera: str, m_per_px: float, ball_radius_m: float, video: dict) -> FileTracks:
    """Track one clip into the tracks of its camera's points; a :class:`FormatError` naming what is wrong."""
    return clip_found(path, camera, m_per_px, ball_radius_m, video)[0]


def clip_found(path: Path, camera: str, m_per_px: float, ball_radius_m: float, video: dict) -> tuple[FileTracks, Found]:
    """Track one clip: its tracks (as :func:`clip_tracks`) and the tracker's :class:`Found` (the quality)."""
    opt = TrackOptions(
        ball_radius_m / m_per_px,
        POINTS[camera],
        video["dot_radius_mm"] * 1e-3 / m_per_px,
        video["marker_radius_mm"] * 1e-3 / m_per_px,
    )
    try:
        clip = open_clip(path)
        found = track_clip(clip, opt)
        require_ball(found, str(path))
    except VideoError as exc:
        raise FormatError([str(exc)]) from None
    measured = float(np.median(found.ball_radii))
    if abs(measured / opt.ball_radius_px - 1.0) > RADIUS_LIMIT:
        raise FormatError(
            [
                f"{path}: the ball measures {measured:.2f} px in radius (median of {len(found.ball_radii)} frames), "
                f"the config's m_per_px {m_per_px:g} makes it {opt.ball_radius_px:.2f} px: the clip says m_per_px "
                f"{ball_radius_m / measured:.4g} (or the ball is not the impacts table's)"
            ]
        )
    rows = found.rows
    point = np.array(rows["point"], dtype=object)
    tracks = {}
    for p in POINTS[camera]:
        sel = point == p
        tracks[p] = tuple(
            np.array(rows[k], dtype=t)[sel] for k, t in (("frame", np.int64), ("x_px", float), ("y_px", float))
        )
    info = clip.info
    source = {"fps": info.source.get("fps", "the clip"), "exposure_s": info.source.get("exposure_s", "the clip")}
    return FileTracks(str(path), tracks, fps=info.fps, source=source, exposure_s=info.exposure_s or None), found


def _track(job: tuple) -> tuple[FileTracks, dict] | FormatError:
    """Track one clip: its tracks and its quality table's columns (a job of :class:`ClipReader`).

    Module-level, so a process pool can run it.
    """
    path, impact_id, camera, *rest = job
    try:
        tracks, found = clip_found(path, camera, *rest)
    except FormatError as exc:
        return exc
    return tracks, found_columns(found, impact_id, camera)[1]


class ClipReader:
    """The reader of a ``format: video`` block's clips: (path, impact id, camera, camera config) each -> FileTracks.

    Called with the folder's clips, it tracks them side by side in ``workers`` processes (the
    import job's threads); the clips are independent, so the tracks are those of one clip at a time.
    ``quality`` holds the quality table's columns of each clip tracked (in the order tracked).
    """

    def __init__(self, block: dict, ball_radius_m: dict[str, float], workers: int = 1) -> None:
        self.video = block["video"]
        self.ball_radius_m = ball_radius_m
        self.workers = max(int(workers), 1)
        self.quality: list[dict[str, np.ndarray]] = []

    def _job(self, path: Path, impact_id: str, camera: str, cam: dict) -> tuple | FormatError:
        if impact_id not in self.ball_radius_m:
            return FormatError([f"{path}: impact {impact_id!r} has no ball in the impacts table"])
        return (path, impact_id, camera, float(cam["m_per_px"]), self.ball_radius_m[impact_id], self.video)

    def __call__(self, items: list[tuple[Path, str, str, dict]]) -> list[FileTracks | FormatError]:
        """Track every (path, impact id, camera, camera config), in order; a clip's problems as its FormatError."""
        jobs = [self._job(*item) for item in items]
        todo = [j for j in jobs if not isinstance(j, FormatError)]
        if self.workers > 1 and len(todo) > 1:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            ctx = multiprocessing.get_context("fork")
            with ProcessPoolExecutor(min(self.workers, len(todo)), mp_context=ctx) as pool:
                got = list(pool.map(_track, todo))
        else:
            got = [_track(j) for j in todo]
        self.quality += [g[1] for g in got if not isinstance(g, FormatError)]
        done = iter(g if isinstance(g, FormatError) else g[0] for g in got)
        return [j if isinstance(j, FormatError) else next(done) for j in jobs]


def clip_reader(block: dict, ball_radius_m: dict[str, float], workers: int = 1) -> ClipReader:
    """Return the reader of a ``format: video`` block's clips (``ball_radius_m``: each impact id's ball radius).

    ``workers``: processes that track clips side by side (the import job's threads).
    """
    return ClipReader(block, ball_radius_m, workers)


class ClipImport:
    """A ``clip_reader`` for :func:`~ballbat.tracks.formats.layout.import_block` that keeps the reader it makes.

    So the import's caller gets the tracker's quality of every clip (:meth:`quality`) beside the tracks.
    """

    def __init__(self, workers: int = 1) -> None:
        self.workers = workers
        self.readers: list[ClipReader] = []

    def __call__(self, block: dict, ball_radius_m: dict[str, float]) -> ClipReader:
        """Return the reader of a block's clips (:func:`clip_reader`), kept."""
        self.readers.append(clip_reader(block, ball_radius_m, self.workers))
        return self.readers[-1]

    def quality(self) -> dict[str, np.ndarray]:
        """Return the quality table of every clip read (:func:`ballbat.video.track.found_columns`), clip after clip."""
        return joined_quality([t for r in self.readers for t in r.quality])
