"""Clips as the files labs have: TIFF stacks (tifffile) and FFV1 / H.264 video (PyAV); written and streamed back.

:func:`open_clip` returns a :class:`Clip`: the settings the file holds (:class:`ClipInfo`,
with where each came from) and :meth:`Clip.frames`, which yields one frame at a time (a
clip is never read whole). Every problem is a :class:`VideoError` naming the file and the
frame. What each file holds (docs/video.md):

* TIFF stack (``.tif``, ``.tiff``): one page per frame, 8 or 16 bit grey. The frame rate,
  exposure, trigger frame and frame numbers from the JSON description :func:`write_clip`
  writes (tifffile's ``shaped`` metadata); a stack without them has none.
* FFV1 in Matroska (``.mkv``, lossless, 8 or 16 bit grey) and H.264 in MP4 (``.mp4``, 8 bit,
  lossy): the frame rate from the stream; per-frame timestamps from the packets where the
  container's time base resolves a frame (MP4's does; Matroska's 1 ms does not at high
  frame rates, so the frame index / rate stands in, and ``source`` says so).
"""

from __future__ import annotations

import fractions
import json
import os
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np

from ..pipeline.atomic import atomic_target
from .cine import CINE_EXT, cine_frames, cine_info
from .clip import ClipInfo, VideoError
from .mraw import MRAW_EXT, mraw_frames, mraw_info

VIDEO_EXT = {".mkv": "ffv1", ".mp4": "h264"}
TIFF_EXT = (".tif", ".tiff")


def write_clip(
    path: str | os.PathLike[str],
    frames: Iterable[np.ndarray],
    fps: float,
    *,
    exposure_s: float | None = None,
    trigger_frame: int | None = None,
    frame_numbers: np.ndarray | None = None,
    crf: int = 18,
) -> Path:
    """Write streamed frames (uint8 or uint16 grey) as a TIFF stack, FFV1 ``.mkv`` or H.264 ``.mp4``.

    ``crf`` is H.264's constant rate factor (lower: better; 18 is visually lossless, 23 the
    encoder's default). The file is written under a temporary name and renamed at the end:
    a failed write leaves nothing.
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in TIFF_EXT and ext not in VIDEO_EXT:
        raise VideoError(f"{path}: unknown clip extension {ext!r} (written: .tif, .tiff, .mkv, .mp4)")
    meta = {"fps": float(fps), "exposure_s": exposure_s, "trigger_frame": trigger_frame}
    if frame_numbers is not None:
        meta["frame_numbers"] = [int(v) for v in frame_numbers]
    with atomic_target(path, suffix=ext) as tmp:
        if ext in TIFF_EXT:
            _write_tiff(tmp, frames, meta)
        else:
            _write_av(tmp, frames, fps, VIDEO_EXT[ext], crf, meta)
    return path


def _write_tiff(tmp: Path, frames: Iterable[np.ndarray], meta: dict) -> None:
    import tifffile

    with tifffile.TiffWriter(tmp) as tw:
        for k, f in enumerate(frames):
            # one page per frame; the settings in the first page's JSON description
            tw.write(f, contiguous=False, metadata={"ballbat": json.dumps(meta)} if k == 0 else None)


def _write_av(tmp: Path, frames: Iterable[np.ndarray], fps: float, codec: str, crf: int, meta: dict) -> None:
    import av

    rate = fractions.Fraction(fps).limit_denominator(1000)
    with av.open(str(tmp), "w", format="matroska" if codec == "ffv1" else "mp4") as out:
        out.metadata["comment"] = json.dumps(meta)
        stream = None
        for f in frames:
            if stream is None:
                deep = f.dtype == np.uint16
                if deep and codec != "ffv1":
                    raise VideoError(f"{tmp.name}: H.264 here is 8 bit; write 16-bit frames as FFV1 (.mkv) or TIFF")
                stream = out.add_stream("ffv1" if codec == "ffv1" else "libx264", rate=rate)
                stream.width, stream.height = f.shape[1], f.shape[0]
                stream.pix_fmt = ("gray16le" if deep else "gray") if codec == "ffv1" else "yuv420p"
                if codec != "ffv1":
                    stream.options = {"crf": str(int(crf)), "preset": "medium"}
                fmt = "gray16le" if deep else "gray"
            frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(f), format=fmt)
            out.mux(stream.encode(frame))
        if stream is not None:
            out.mux(stream.encode())


class Clip:
    """An opened clip: its settings (:attr:`info`) and its frames, streamed by :meth:`frames`."""

    def __init__(self, info: ClipInfo):
        """Hold the settings read from the file (use :func:`open_clip`)."""
        self.info = info

    def frames(self) -> Iterator[tuple[int, float | None, np.ndarray]]:
        """Yield (index, timestamp in s or None, frame) one at a time, frame a 2-d uint8 or uint16 array.

        The timestamp is the file's own (a video packet's), None where the file has none or
        its time base is coarser than a quarter frame.
        """
        if self.info.format == "tiff":
            yield from _tiff_frames(self.info)
        elif self.info.format == "mraw":
            yield from mraw_frames(self.info)
        elif self.info.format == "cine":
            yield from cine_frames(self.info)
        else:
            yield from _av_frames(self.info)


def open_clip(path: str | os.PathLike[str]) -> Clip:
    """Open a clip and read its settings (not its frames); a :class:`VideoError` if it cannot be."""
    path = Path(path)
    if not path.is_file():
        raise VideoError(f"{path}: file not found")
    ext = path.suffix.lower()
    if ext in TIFF_EXT:
        return Clip(_tiff_info(path))
    if ext in MRAW_EXT:
        return Clip(mraw_info(path))
    if ext in CINE_EXT:
        return Clip(cine_info(path))
    if ext in VIDEO_EXT or ext in (".avi", ".mov"):
        return Clip(_av_info(path))
    raise VideoError(
        f"{path}: unknown clip extension {ext!r} (known: .tif, .tiff, .cihx, .cih, .cine, .mkv, .mp4, .avi, .mov)"
    )


def _apply_meta(info: ClipInfo, meta: dict, where: str) -> None:
    """Fill the settings a ballbat JSON description holds, noting where each came from."""
    for key in ("fps", "exposure_s", "trigger_frame"):
        if meta.get(key) is not None:
            setattr(info, key, meta[key])
            info.source[key] = where
    if meta.get("frame_numbers") is not None:
        info.frame_numbers = np.asarray(meta["frame_numbers"], dtype=np.int64)
        info.source["frame_numbers"] = where


def _tiff_info(path: Path) -> ClipInfo:
    import tifffile

    try:
        with tifffile.TiffFile(path) as tf:
            n = len(tf.pages)
            page = tf.pages[0]
            desc = page.description
            shape, dtype = page.shape, page.dtype
    except Exception as exc:  # tifffile raises many kinds for a broken file
        raise VideoError(f"{path}: frame 0: cannot be read as TIFF ({exc})") from None
    if len(shape) != 2 or dtype not in (np.uint8, np.uint16):
        raise VideoError(f"{path}: frame 0: {shape} {dtype} is not grey 8 or 16 bit (colour is not read)")
    info = ClipInfo(str(path), "tiff", shape[1], shape[0], n, 8 * dtype.itemsize)
    try:
        meta = json.loads(json.loads(desc).get("ballbat", "{}")) if desc.startswith("{") else {}
    except (ValueError, AttributeError):
        meta = {}
    _apply_meta(info, meta, "TIFF description (ballbat)")
    return info


def _tiff_frames(info: ClipInfo) -> Iterator[tuple[int, float | None, np.ndarray]]:
    import tifffile

    k = 0
    try:
        with tifffile.TiffFile(info.path) as tf:
            for k, page in enumerate(tf.pages):
                a = page.asarray()
                if a.shape != (info.height, info.width):
                    raise VideoError(f"{info.path}: frame {k}: size {a.shape[::-1]}, not {info.width} x {info.height}")
                yield k, None, a
    except VideoError:
        raise
    except Exception as exc:
        raise VideoError(f"{info.path}: frame {k}: cannot be read ({exc})") from None


def _av_facts(c, path: Path) -> dict:
    """Return what the container and its first video stream say: codec, pixel format, rate, frames, comment."""
    if not c.streams.video:
        raise VideoError(f"{path}: frame 0: no video stream")
    s = c.streams.video[0]
    try:
        pix = s.format.name
    except AttributeError:  # PyAV gives no format when FFmpeg has no decoder for the codec
        raise VideoError(f"{path}: frame 0: no decoder for its video codec (unknown or unsupported)") from None
    rate = s.average_rate or s.guessed_rate
    n, slack = s.frames, 0
    shown = round(c.duration / 1e6 * float(rate)) if c.duration and rate else 0  # the duration, in frames
    if shown and (not n or n > shown + 1):
        # no count, or more frames stored than the clip lasts: an edit list shows part of them (a phone's trimmed
        # clip keeps the frames cut off before its start), and only those are decoded
        n, slack = shown, int(np.ceil(float(s.time_base) * float(rate)))
    return {
        "name": s.codec_context.name,
        "pix": pix,
        "rate": rate,
        "n": n or None,
        "slack": slack,
        "size": (s.width, s.height),
        "time_base": str(s.time_base),
        "comment": next((v for k, v in c.metadata.items() if k.lower() == "comment"), ""),
    }


def _av_info(path: Path) -> ClipInfo:
    import av

    try:
        with av.open(str(path)) as c:
            f = _av_facts(c, path)
    except av.error.FFmpegError as exc:
        raise VideoError(f"{path}: frame 0: cannot be opened as video ({exc})") from None
    if f["pix"] not in ("gray", "gray16le", "yuv420p", "yuvj420p", "yuv422p", "yuv444p"):
        raise VideoError(f"{path}: pixel format {f['pix']!r} is not read (grey or YUV; colour is taken as its luma)")
    info = ClipInfo(str(path), f["name"], *f["size"], f["n"], 16 if f["pix"] == "gray16le" else 8)
    if f["rate"]:
        info.fps, info.source["fps"] = float(f["rate"]), f"{f['name']} stream frame rate"
    try:
        meta = json.loads(f["comment"]) if f["comment"].startswith("{") else {}
    except ValueError:
        meta = {}
    _apply_meta(info, {k: v for k, v in meta.items() if k != "fps"}, "container comment (ballbat)")
    info.source["time_base"] = f["time_base"]
    if info.frame_numbers is not None:  # ballbat's own files list every frame: the count is exact
        info.n_frames, f["slack"] = int(info.frame_numbers.size), 0
    info.source["frames_slack"] = str(f["slack"])
    return info


def _av_frames(info: ClipInfo) -> Iterator[tuple[int, float | None, np.ndarray]]:
    import av

    fmt = "gray16le" if info.bit_depth == 16 else "gray"
    k = 0
    try:
        with av.open(info.path) as c:
            s = c.streams.video[0]
            s.thread_type = "AUTO"
            fine = info.fps is not None and s.time_base is not None and float(s.time_base) * info.fps <= 0.25
            k = -1
            for k, frame in enumerate(c.decode(s)):
                t = float(frame.time) if fine and frame.time is not None else None
                yield k, t, frame.to_ndarray(format=fmt)
            slack = int(info.source.get("frames_slack", "0"))
            if info.n_frames and k + 1 < info.n_frames - slack:
                raise VideoError(
                    f"{info.path}: frame {k + 1}: the stream ends after {k + 1} frames, its header says "
                    f"{info.n_frames}: truncated or corrupt"
                )
    except av.error.FFmpegError as exc:
        raise VideoError(f"{info.path}: frame {k}: cannot be decoded ({exc})") from None
