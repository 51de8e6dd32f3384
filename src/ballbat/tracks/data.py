"""Settings and containers of raw camera tracks (Sec. II).

Two cameras look along the bat's axis at impact: ``swing`` (Camera 1) tracks the dot on the
bat's end cap (``bat_tip``) and the ball's centre (``ball``); ``spin`` (Camera 2) tracks the
ball's centre and two dots on the ball (``dot_a``, ``dot_b``). Pixels: x to the right, y
downward; the swing goes towards +x, or towards -x when the camera is ``mirror``.

In memory the tracks of one camera are dense arrays ``(impact, frame column)`` with NaN
where a point was not tracked; column ``k`` of impact ``i`` is frame ``frame0[i] + k`` of
that camera (frame origins are arbitrary and the cameras are not synchronised).
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

    No field has a default: the defaults are the config schema's alone.
    """

    fps: float
    m_per_px: float
    mirror: bool
    m_per_px_err: float
    fps_err: float

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


#: The most frames one impact's track may span in one camera (first to last tracked frame): every
#: impact's tracks are stored padded to the longest (one array per camera), so a track of 1e6 rest
#: frames would make every impact that long. 20 000 frames are 6.7 s at 3000 frames per second.
MAX_TRACK_FRAMES = 20_000
#: The most bytes the padded tracks of one camera may take (impacts x frames x points x 2 x 8 bytes).
MAX_DENSE_BYTES = 2 * 2**30


def dense_problems(
    ids: np.ndarray, impact_index: np.ndarray, camera: np.ndarray, frame: np.ndarray, source: str
) -> list[str]:
    """Name what would make the padded arrays of :func:`to_dense` too large, before they are sized.

    The longest track of each camera (impact id, frames spanned) against :data:`MAX_TRACK_FRAMES`,
    and the padded size against :data:`MAX_DENSE_BYTES`. ``ids``: the impact ids by index.
    """
    problems = []
    for cam, points in POINTS.items():
        sel = camera == cam
        if not sel.any():
            continue
        ii, ff = impact_index[sel], frame[sel].astype(np.int64)
        lo = np.full(ids.size, np.iinfo(np.int64).max, dtype=np.int64)
        hi = np.full(ids.size, np.iinfo(np.int64).min, dtype=np.int64)
        np.minimum.at(lo, ii, ff)
        np.maximum.at(hi, ii, ff)
        span = np.where(hi >= lo, hi - lo + 1, 0)
        k = int(np.argmax(span))
        size = ids.size * int(span[k]) * len(points) * 2 * 8
        what = f"{source}: impact {str(ids[k])!r} spans {int(span[k])} frames in the {cam} camera ({lo[k]}-{hi[k]})"
        if span[k] > MAX_TRACK_FRAMES:
            problems.append(
                f"{what}, more than the {MAX_TRACK_FRAMES} one impact's track may span: track only the "
                "frames around the impact (a rest position held for long, or a wrong frame number?)"
            )
        elif size > MAX_DENSE_BYTES:
            problems.append(
                f"{what}: {ids.size} impacts padded to it would take {size / 2**30:.1f} GiB, more than "
                f"{MAX_DENSE_BYTES // 2**30} GiB; track fewer frames per impact, or split the dataset"
            )
    return problems


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


def camera_block(cfg: dict) -> dict:
    """``cameras`` and ``rig`` of a ``tracks`` or ``render`` block, with only the reduction's settings."""
    keep = ("fps", "m_per_px", "mirror", "m_per_px_err", "fps_err")
    return {
        "cameras": {n: {k: v for k, v in c.items() if k in keep} for n, c in cfg["cameras"].items()},
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
            "video": {k: render["video"][k] for k in ("dot_radius_mm", "marker_radius_mm")},
        }
    )
    return block


def with_found_settings(block: dict, found: dict) -> dict:
    """Return the reduce rule's settings block with the frame rates and pixel scales found in the files."""
    out = {**block, "cameras": {c: dict(v) for c, v in block["cameras"].items()}}
    for cam, vals in found["cameras"].items():
        for key in ("fps", "m_per_px"):
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
