"""Settings and containers of raw camera tracks (Sec. II).

Two cameras look along the bat's axis at impact: ``swing`` (Camera 1) tracks the dot on the
bat's end cap (``bat_tip``) and the ball's centre (``ball``); ``spin`` (Camera 2) tracks the
ball's centre and two dots on the ball (``dot_a``, ``dot_b``). Pixels: x to the right, y
downward; the swing goes towards +x, or towards -x when the camera is ``mirror``.

In memory the tracks of one camera are dense arrays ``(impact, frame column)`` with NaN
where a point was not tracked; column ``k`` of impact ``i`` is frame ``frame0[i] + k`` of
that camera (frame origins are arbitrary and the cameras are not synchronised). A dataset
whose impacts, padded to its longest track, would take more than :data:`BLOCK_BYTES` is held
in blocks of impacts (:class:`TrackBlocks`), each padded only to its own longest track.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..units import INCH

#: Prior range of a ball-on-bat contact time (s), uniform: generous bounds around the
#: literature's 0.6-0.7 ms of a baseball on a bat and about 1 ms or more of a softball
#: (docs/tracks.md, "The contact time"). The reduction fits each impact's contact time within
#: it (:func:`ballbat.tracks.fit_contact.fit_contact`); a study's rendered contacts must lie inside.
CONTACT_PRIOR = (0.2e-3, 2.0e-3)

#: Points each camera tracks.
POINTS = {"swing": ("bat_tip", "ball"), "spin": ("ball", "dot_a", "dot_b")}
CAMERAS = tuple(POINTS)


@dataclass(frozen=True)
class Camera:
    """Settings of one camera.

    Parameters
    ----------
    fps : float
        Frame rate (frames per second).
    m_per_px : float
        Pixel scale in the plane of the swing (m per pixel).
    mirror : bool
        True when the swing goes towards -x on the image.
    m_per_px_err : float
        Relative standard uncertainty of ``m_per_px`` (a systematic shared by every impact).
    fps_err : float
        Relative standard uncertainty of ``fps`` (a systematic shared by every impact).
    exposure_s : float
        Exposure time of a frame (s); 0 where not known (a frame taken as an instant). A frame
        whose exposure may reach into the contact is not a frame before it (the tip's fit).

    No field has a default: the defaults are the config schema's alone.
    """

    fps: float
    m_per_px: float
    mirror: bool
    m_per_px_err: float
    fps_err: float
    exposure_s: float

    @property
    def sign(self) -> float:
        """+1 when the swing goes towards +x on the image, -1 when mirrored."""
        return -1.0 if self.mirror else 1.0


@dataclass(frozen=True)
class Rig:
    """Distances from the swing machine's pivot axis (m), with their standard uncertainties (m, systematics)."""

    pivot_to_tip: float
    pivot_to_impact: float
    pivot_to_tip_err: float
    pivot_to_impact_err: float

    @classmethod
    def from_inches(
        cls,
        pivot_to_tip_in: float,
        pivot_to_impact_in: float,
        pivot_to_tip_err_in: float,
        pivot_to_impact_err_in: float,
    ) -> Rig:
        """Return a rig from the config's inches."""
        return cls(
            pivot_to_tip_in * INCH, pivot_to_impact_in * INCH, pivot_to_tip_err_in * INCH, pivot_to_impact_err_in * INCH
        )


@dataclass
class CameraTracks:
    """Dense tracks of one camera: ``x[point]``, ``y[point]`` of shape (impact, column), pixels."""

    frame0: np.ndarray
    x: dict[str, np.ndarray]
    y: dict[str, np.ndarray]

    @property
    def n_columns(self) -> int:
        """Number of frame columns."""
        return next(iter(self.x.values())).shape[1]

    def frames(self) -> np.ndarray:
        """Frame number of every column, (impact, column)."""
        return self.frame0[:, None] + np.arange(self.n_columns)[None, :]


@dataclass
class Tracks:
    """Tracks of a set of impacts: ids, ball and bat per impact, and both cameras' tracks.

    ``truth`` holds per-impact true values of rendered (synthetic) tracks, keyed by the
    variable name they get in the reduced file (``truth_v_bat``...); empty for a lab's data.
    """

    impact_id: np.ndarray
    ball: np.ndarray
    bat: np.ndarray
    cameras: dict[str, CameraTracks]
    truth: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def n(self) -> int:
        """Number of impacts."""
        return len(self.impact_id)

    @property
    def blocks(self) -> list[Tracks]:
        """The blocks the tracks are held in: this one (:class:`TrackBlocks` holds several)."""
        return [self]

    @property
    def index(self) -> list[np.ndarray]:
        """Each block's impacts, as positions in the dataset: all, in order."""
        return [np.arange(self.n)]

    def frame0(self, camera: str) -> np.ndarray:
        """Frame number of column 0 of each impact in ``camera``, (impact,)."""
        return self.cameras[camera].frame0

    def locate(self, i: int) -> tuple[Tracks, int]:
        """Return the block holding impact ``i`` and its row there."""
        return self, int(i)


@dataclass
class TrackBlocks:
    """Tracks of a set of impacts held in blocks of impacts, each padded only to its own longest track.

    ``blocks[b]`` is a :class:`Tracks` of the impacts at positions ``index[b]`` of the dataset
    (ascending); every impact is in exactly one block. The per-impact fields (``impact_id``,
    ``ball``, ``bat``, ``truth``, :meth:`frame0`) are the dataset's, in its order; the frames
    are the blocks' (:meth:`locate`). Made by :func:`ballbat.tracks.io.load_tracks` when one
    block would take more than :data:`BLOCK_BYTES` (:func:`plan_blocks`).
    """

    blocks: list[Tracks]
    index: list[np.ndarray]

    @property
    def n(self) -> int:
        """Number of impacts."""
        return sum(len(i) for i in self.index)

    def gather(self, parts: list[np.ndarray]) -> np.ndarray:
        """One array per block (impact first) as one array in the dataset's order."""
        return gather(parts, self.index, self.n)

    @property
    def impact_id(self) -> np.ndarray:
        """Impact ids, (impact,)."""
        return self.gather([b.impact_id for b in self.blocks])

    @property
    def ball(self) -> np.ndarray:
        """Ball of each impact, (impact,)."""
        return self.gather([b.ball for b in self.blocks])

    @property
    def bat(self) -> np.ndarray:
        """Bat of each impact, (impact,)."""
        return self.gather([b.bat for b in self.blocks])

    @property
    def truth(self) -> dict[str, np.ndarray]:
        """True values of rendered tracks, (impact,) each (:attr:`Tracks.truth`)."""
        return {k: self.gather([b.truth[k] for b in self.blocks]) for k in self.blocks[0].truth}

    def frame0(self, camera: str) -> np.ndarray:
        """Frame number of column 0 of each impact in ``camera``, (impact,)."""
        return self.gather([b.cameras[camera].frame0 for b in self.blocks])

    def locate(self, i: int) -> tuple[Tracks, int]:
        """Return the block holding impact ``i`` and its row there."""
        for blk, idx in zip(self.blocks, self.index, strict=True):
            k = int(np.searchsorted(idx, i))
            if k < idx.size and idx[k] == i:
                return blk, k
        raise IndexError(f"impact {i} of {self.n}")


def gather(parts: list[np.ndarray], index: list[np.ndarray], n: int) -> np.ndarray:
    """Return the blocks' arrays ``parts`` (impact first, rows ``index[b]`` of the dataset) as one, in its order."""
    if len(parts) == 1 and np.array_equal(index[0], np.arange(n)):
        return parts[0]
    out = np.empty((n, *parts[0].shape[1:]), dtype=np.result_type(*parts))
    for p, idx in zip(parts, index, strict=True):
        out[idx] = p
    return out


def to_long(tracks: Tracks) -> dict[str, np.ndarray]:
    """Long-format rows ``impact_id, camera, point, frame, x_px, y_px`` (untracked cells omitted)."""
    cols: dict[str, list] = {k: [] for k in ("impact_id", "camera", "point", "frame", "x_px", "y_px")}
    for cam, ct in tracks.cameras.items():
        frames = ct.frames()
        for p in POINTS[cam]:
            ok = np.isfinite(ct.x[p]) & np.isfinite(ct.y[p])
            ii, kk = np.nonzero(ok)
            cols["impact_id"].append(tracks.impact_id[ii])
            cols["camera"].append(np.full(ii.size, cam))
            cols["point"].append(np.full(ii.size, p))
            cols["frame"].append(frames[ii, kk])
            cols["x_px"].append(ct.x[p][ii, kk])
            cols["y_px"].append(ct.y[p][ii, kk])
    out = {k: np.concatenate(v) for k, v in cols.items()}
    order = np.lexsort((out["frame"], out["point"], out["camera"], out["impact_id"]))
    return {k: v[order] for k, v in out.items()}


#: The most frames one impact's track may span in one camera (first to last tracked frame): 20 000
#: frames are 6.7 s at 3000 frames per second, where the reduction fits some tens of frames
#: around the impact. Longer is a mistake (a rest position held through the whole session, a
#: wrong frame number), named before any array is made. Blocks (:data:`BLOCK_BYTES`) keep a long
#: track from costing the other impacts anything; this limit is a sanity check, not a memory one.
MAX_TRACK_FRAMES = 20_000
#: The most bytes the padded tracks of one block of impacts may take (impacts x frames x points
#: x 2 coordinates x 8 bytes, both cameras): a dataset within it is one block, as all shipped
#: ones are (the default run's 108 impacts: 0.6 MB); a larger one is split (:func:`plan_blocks`).
#: It bounds the working arrays of one block's fits; the reduction keeps every block's fits for
#: the cross-checks, about ten times the padded tracks at its peak (``bench/bench_track_blocks.py``).
#: One impact alone is never above it (:data:`MAX_TRACK_FRAMES` x 5 points x 16 bytes is 1.6 MB).
BLOCK_BYTES = 32 * 2**20
#: The most bytes one camera's tracks may take in their blocks (the sum over the blocks of
#: impacts x frames x points x 2 x 8 bytes): past it the dataset is refused by name (split it),
#: before any array is made. The same 2 GiB as when every impact was padded to the longest track,
#: now of the blocks, at most twice the tracks' own size.
MAX_DENSE_BYTES = 2 * 2**30


def track_spans(
    impact_index: np.ndarray, camera: np.ndarray, frame: np.ndarray, n: int
) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per camera, each impact's first and last tracked frame and the frames spanned (0: no rows), (impact,) each."""
    out = {}
    for cam in POINTS:
        sel = camera == cam
        ii, ff = impact_index[sel], frame[sel].astype(np.int64)
        lo = np.full(n, np.iinfo(np.int64).max, dtype=np.int64)
        hi = np.full(n, np.iinfo(np.int64).min, dtype=np.int64)
        np.minimum.at(lo, ii, ff)
        np.maximum.at(hi, ii, ff)
        out[cam] = (lo, hi, np.where(hi >= lo, hi - lo + 1, 0))
    return out


def dense_problems(
    ids: np.ndarray, impact_index: np.ndarray, camera: np.ndarray, frame: np.ndarray, source: str
) -> list[str]:
    """Name each camera's longest track if it spans more than :data:`MAX_TRACK_FRAMES` frames (before any array).

    ``ids``: the impact ids by index; ``source``: the file, for messages.
    """
    problems = []
    for cam, (lo, hi, span) in track_spans(impact_index, camera, frame, ids.size).items():
        if not span.any():
            continue
        k = int(np.argmax(span))
        if span[k] > MAX_TRACK_FRAMES:
            problems.append(
                f"{source}: impact {str(ids[k])!r} spans {int(span[k])} frames in the {cam} camera "
                f"({lo[k]}-{hi[k]}), more than the {MAX_TRACK_FRAMES} one impact's track may span: track only "
                "the frames around the impact (a rest position held for long, or a wrong frame number?)"
            )
    return problems


def blocks_problems(spans: dict[str, np.ndarray], plan: list[np.ndarray], source: str) -> list[str]:
    """Name each camera whose tracks, in the blocks of ``plan``, would take more than :data:`MAX_DENSE_BYTES`."""
    problems = []
    for cam, span in spans.items():
        size = sum(idx.size * int(np.maximum(span[idx], 1).max()) for idx in plan) * len(POINTS[cam]) * 2 * 8
        if size > MAX_DENSE_BYTES:
            n = sum(idx.size for idx in plan)
            problems.append(
                f"{source}: the {cam} camera's tracks of {n} impacts would take {size / 2**30:.2g} GiB (in "
                f"{len(plan)} block(s) of impacts), more than {MAX_DENSE_BYTES / 2**30:g} GiB: track fewer "
                "frames per impact, or split the dataset"
            )
    return problems


def plan_blocks(spans: dict[str, np.ndarray], budget: int | None = None) -> list[np.ndarray]:
    """Group the impacts into blocks whose padded tracks take at most ``budget`` bytes each.

    ``spans``: per camera, the frames each impact's track spans, (impact,). One block of every
    impact when padding them all to the longest fits ``budget`` (default :data:`BLOCK_BYTES`).
    Otherwise the impacts, in order of their own size, fill blocks while a block's padded size
    stays within ``budget`` and within twice its tracks' own size, so that padding costs at most
    as much again as the tracks: a track ten times longer than the rest gets a block of its own
    (or of its like), not every impact padded to it. Each block lists its impacts in the
    dataset's order.
    """
    budget = BLOCK_BYTES if budget is None else budget
    cams = list(spans)
    per = np.array([len(POINTS[c]) * 2 * 8 for c in cams], dtype=np.int64)  # bytes per frame column
    s = np.stack([np.maximum(np.asarray(spans[c], dtype=np.int64), 1) for c in cams], axis=1)  # to_dense: >= 1
    n = s.shape[0]
    if n * int(s.max(axis=0) @ per) <= budget:
        return [np.arange(n)]
    own = s @ per
    blocks, cur, hi, size = [], [], np.zeros(len(cams), dtype=np.int64), 0
    for i in np.argsort(own, kind="stable"):
        top = np.maximum(hi, s[i])
        padded = (len(cur) + 1) * int(top @ per)
        if cur and (padded > budget or padded > 2 * (size + int(own[i]))):
            blocks.append(np.sort(np.array(cur)))
            cur, top, size = [], s[i].copy(), 0
        cur.append(i)
        hi, size = top, size + int(own[i])
    blocks.append(np.sort(np.array(cur)))
    return sorted(blocks, key=lambda b: int(b[0]))


def to_dense(
    impact_index: np.ndarray,
    camera: np.ndarray,
    point: np.ndarray,
    frame: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    n: int,
) -> dict[str, CameraTracks]:
    """Dense per-camera arrays from long rows (already checked: no repeated frames, known names).

    ``impact_index`` is each row's impact as an index 0..n-1. An impact without rows of a
    camera gets ``frame0`` 0 and all-NaN columns.
    """
    out = {}
    for cam, points in POINTS.items():
        sel = camera == cam
        ii, ff = impact_index[sel], frame[sel].astype(np.int64)
        frame0 = np.full(n, np.iinfo(np.int64).max, dtype=np.int64)
        np.minimum.at(frame0, ii, ff)
        frame0[frame0 == np.iinfo(np.int64).max] = 0
        col = ff - frame0[ii]
        width = int(col.max()) + 1 if col.size else 1
        xs, ys = {}, {}
        for p in points:
            xs[p] = np.full((n, width), np.nan)
            ys[p] = np.full((n, width), np.nan)
            ps = point[sel] == p
            xs[p][ii[ps], col[ps]] = x[sel][ps]
            ys[p][ii[ps], col[ps]] = y[sel][ps]
        out[cam] = CameraTracks(frame0, xs, ys)
    return out


#: A render block's cameras sample the motion at instants: no exposure (its clips' is read from them).
RENDERED_EXPOSURE_US = 0.0


def camera_block(cfg: dict) -> dict:
    """``cameras`` and ``rig`` of a ``tracks`` or ``render`` block, with only the reduction's settings."""
    keep = ("fps", "m_per_px", "mirror", "m_per_px_err", "fps_err", "exposure_us")
    cams = {n: {k: v for k, v in c.items() if k in keep} for n, c in cfg["cameras"].items()}
    for c in cams.values():
        if "exposure_us" not in c:  # a render block's camera (a tracks block's has the schema's)
            c["exposure_us"] = RENDERED_EXPOSURE_US
    return {
        "cameras": cams,
        "rig": dict(cfg["rig"]),
        **({"min_frames": cfg["min_frames"]} if "min_frames" in cfg else {}),
    }


def clips_block(render: dict, clips_dir: str) -> dict:
    """Return the ``tracks`` block (``format: video``) that reads a rendered dataset's clips back.

    The cameras' scales, mirrors and uncertainties, the rig and the frame limits are the
    ``render`` block's: the lab's settings, as it would state them for its own clips.
    """
    block = camera_block(render)
    block.update(
        {
            "dir": clips_dir,
            "format": "video",
            "pattern": "{impact_id}_{camera}.{ext}",
            "impacts": f"{clips_dir}/impacts.csv",
            "video": {k: render["video"][k] for k in ("dot_radius_mm", "marker_radius_mm", "clips_per_job")},
        }
    )
    return block


def with_found_settings(block: dict, found: dict) -> dict:
    """Return the reduce rule's settings block with the frame rates and pixel scales found in the files."""
    out = {**block, "cameras": {c: dict(v) for c, v in block["cameras"].items()}}
    for cam, vals in found["cameras"].items():
        for key in ("fps", "m_per_px", "exposure_us"):
            if key in vals:
                out["cameras"].setdefault(cam, {})[key] = vals[key]
    return out


def name_found_settings(problems: list[str], found: dict) -> list[str]:
    """Return ``problems`` with each camera setting the files gave marked as read from them.

    A diagnosis names config keys (``cameras.spin.fps``); for a folder of tool files the value
    may come from the files (``found``: :meth:`~ballbat.tracks.formats.layout.Imported.settings_yaml`),
    a key the user never set: the line then says where the value was read.
    """
    marks = {}
    for cam, vals in (found.get("cameras") or {}).items():
        for key in ("fps", "m_per_px"):
            src = str(vals.get(f"{key}_from", ""))
            if key in vals and src and not src.startswith("config"):
                marks[f"cameras.{cam}.{key}"] = f"the value read from the files ({src}), not set in the config"
    out = []
    for line in problems:
        for key, note in marks.items():
            line = line.replace(f"{key} ", f"{key} [{note}] ").replace(f"{key}:", f"{key} [{note}]:")
        out.append(line)
    return out


#: The formats of a ``tracks`` block's folder of tool files (``format``) and their files'
#: extensions; here, not in :mod:`.formats`, so that the workflow's start-up (common.smk) reads
#: them without importing the readers.
FORMATS = {
    "tracker": (".trk", ".trz"),
    "kinovea": (".kva",),
    "tracker_table": (".txt", ".csv", ".tsv"),
    "kinovea_table": (".csv", ".txt"),
    # high-speed clips, tracked on import (ballbat.video.importer)
    "video": (".cine", ".cihx", ".cih", ".tif", ".tiff", ".mkv", ".mp4", ".avi", ".mov"),
}
#: Formats known from the extension alone.
BY_EXTENSION = {".trk": "tracker", ".trz": "tracker", ".kva": "kinovea"}


def tool_file_extensions(fmt: str | None) -> tuple[str, ...]:
    """Extensions of the files a ``dir`` of format ``fmt`` holds (None: the tools' own files)."""
    return FORMATS[fmt] if fmt else tuple(BY_EXTENSION)
