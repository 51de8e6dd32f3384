"""Phantom ``.cine`` clips (Vision Research / AMETEK): the header, setup, tagged blocks and frames, streamed.

Read here rather than with AMETEK's cinereader (it needs numba: about 210 MB with llvmlite)
or pycine (it pulls in OpenCV): a cine file is a little-endian header of fixed layout
followed by a table of 64-bit image offsets; this module reads the header part only
(tens of kB) and then one frame at a time from a memory map. The layout is Vision
Research's "Cine File Format" (structures CINEFILEHEADER, BITMAPINFOHEADER, SETUP, the
tagged information blocks, the image offsets and each image's annotation); the SETUP
fields read here are named as there.

What is read (docs/video.md): the size and bits (8 or 16 bit grey, ``RealBPP`` effective
bits), the frame rate (``FrameRate``, else ``FrameRate16``), the exposure (``ShutterNs``,
else ``Shutter`` in us), the number of images and the first image's number counted from
the trigger (``FirstImageNo``; the trigger is image 0), and each image's time (tagged
block 1002, relative to ``TriggerTime``). A clip saved with only every k-th recorded
frame (PCC's "decimation" at saving) keeps the recording's ``FrameRate`` in its setup; its
timestamps step k frames at a time, so the frame rate is ``FrameRate / k`` and the source
says so. Refused, with the reason: JPEG-compressed and colour clips (uninterpolated Bayer
``Compression = 2``, or a colour sensor's ``CFA``), and 10/12-bit packed pixels (no such grey
file was at hand to check the bit order against).
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .clip import ClipInfo, VideoError

CINE_EXT = (".cine",)

#: CINEFILEHEADER: Type, Headersize, Compression, Version, FirstMovieImage, TotalImageCount,
#: FirstImageNo, ImageCount, OffImageHeader, OffSetup, OffImageOffsets, TriggerTime (TIME64).
_HEADER = struct.Struct("<2sHHHiIiIIIIQ")
#: BITMAPINFOHEADER: biSize, biWidth, biHeight, biPlanes, biBitCount, biCompression, biSizeImage, ...
_BITMAP = struct.Struct("<IiiHHIIiiII")
#: The SETUP fields read: (byte offset in the packed structure, struct code).
_SETUP = {
    "FrameRate16": (0, "H"),
    "Length": (142, "H"),
    "FrameRate": (768, "I"),
    "Shutter": (772, "I"),  # us
    "CFA": (808, "I"),
    "RealBPP": (896, "I"),
    "ShutterNs": (1568, "I"),
}
#: Tagged block types: 1002 the time of each image (TIME64), 1004 range data (ends the blocks).
_TIME_ONLY, _RANGE_DATA = 1002, 1004
_COMPRESSION = {1: "JPEG-compressed", 2: "raw colour (uninterpolated Bayer)"}


def _seconds_from(value: int, origin: int) -> float:
    """Seconds from one TIME64 to another (each whole seconds in the high 32 bits, fractions of 2**-32 s in the low).

    Subtracted as integers first: seconds since 1970 as a float keep only about 0.24 us (2**-22 s),
    a quarter of a frame at 1 million frames per second.
    """
    return (value - origin) / 2.0**32


@dataclass(frozen=True)
class _Layout:
    """Where a cine file's images are, and what the header says of them."""

    width: int
    height: int  # rows; stored bottom-up when biHeight > 0
    bottom_up: bool
    bits: int  # 8 or 16 (the container)
    n_images: int
    first_image_no: int
    pointers: tuple[int, ...]
    times: np.ndarray | None  # seconds from the trigger, one per image
    setup: dict[str, int]
    file_size: int


def _unpack(fmt: struct.Struct | str, raw: bytes, offset: int, path: Path, what: str) -> tuple:
    s = fmt if isinstance(fmt, struct.Struct) else struct.Struct("<" + fmt)
    if offset + s.size > len(raw):
        raise VideoError(f"{path}: the file ends inside its {what} (at byte {len(raw)}): truncated")
    return s.unpack_from(raw, offset)


def _setup(raw: bytes, off: int, path: Path) -> dict[str, int]:
    length = _unpack("H", raw, off + _SETUP["Length"][0], path, "setup")[0]
    out = {"Length": length}
    for name, (pos, code) in _SETUP.items():
        if pos + struct.calcsize(code) <= length:  # an older file's shorter setup lacks the later fields
            out[name] = _unpack(code, raw, off + pos, path, "setup")[0]
    return out


def _tagged_times(raw: bytes, start: int, end: int, n: int, trigger: int, path: Path) -> np.ndarray | None:
    """Each image's time from the trigger (tagged block 1002), or None where the file has no such block."""
    off = start
    while off + 8 <= end:
        size, kind, more = _unpack("IHH", raw, off, path, "tagged blocks")
        if size < 8:
            raise VideoError(f"{path}: a tagged block at byte {off} says it is {size} bytes long: damaged header")
        if kind == _TIME_ONLY:
            if size - 8 != 8 * n:
                raise VideoError(f"{path}: the time block holds {(size - 8) // 8} times for {n} images")
            values = _unpack(f"{n}Q", raw, off + 8, path, "time block")
            return np.array([_seconds_from(v, trigger) for v in values])
        if kind == _RANGE_DATA or not more:
            return None
        off += size
    return None


def _layout(path: Path) -> _Layout:
    size = path.stat().st_size
    with open(path, "rb") as fh:
        raw = fh.read(min(size, 1 << 20))
        typ, _hs, compression, _v, _fmi, _tot, first_no, n, off_bi, off_setup, off_ptr, trig = _unpack(
            _HEADER, raw, 0, path, "header"
        )
        if typ != b"CI":
            raise VideoError(f"{path}: not a Phantom cine file (it starts with {raw[:2]!r}, not b'CI')")
        need = off_ptr + 8 * n
        if need > len(raw) and need <= size:
            fh.seek(0)
            raw = fh.read(need)
    if compression in _COMPRESSION:
        raise VideoError(f"{path}: a {_COMPRESSION[compression]} clip; only grey, uncompressed clips are read")
    _isz, width, height, _pl, bits, bi_comp, img_size = _unpack(_BITMAP, raw, off_bi, path, "image header")[:7]
    setup = _setup(raw, off_setup, path)
    if setup.get("CFA", 0) != 0 or bits in (24, 48):
        raise VideoError(f"{path}: a colour clip (CFA {setup.get('CFA')}, {bits} bits); only grey clips are read")
    npx = abs(width) * abs(height)
    if bi_comp != 0 or bits not in (8, 16) or (img_size and img_size * 8 != npx * bits):
        raise VideoError(
            f"{path}: {bits}-bit pixels, compression {bi_comp}, {img_size} bytes an image for {npx} pixels;"
            " 8 and 16 bit are read (packed 10/12-bit is not: save the clip as 16-bit in PCC)"
        )
    pointers = _unpack(f"{n}Q", raw, off_ptr, path, "image offsets") if n else ()
    times = _tagged_times(raw, off_setup + setup["Length"], off_ptr, n, trig, path)
    return _Layout(abs(width), abs(height), height > 0, bits, n, first_no, pointers, times, setup, size)


def _decimation(times: np.ndarray | None, fps: float) -> int:
    """Return k where the images' times step k recorded frames apart, each within a quarter frame (else 1)."""
    if times is None or times.size < 2 or not fps > 0:
        return 1
    steps = np.diff(times) * fps
    k = round(float(np.median(steps)))
    return k if k >= 2 and np.all(np.abs(steps - k) < 0.25) else 1


def _ordinal(k: int) -> str:
    """Return 2nd, 3rd, 10th, 21st, ..."""
    suffix = "th" if 10 <= k % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(k % 10, "th")
    return f"{k}{suffix}"


def cine_info(path: str | Path) -> ClipInfo:
    """Read a cine file's header and check it; a :class:`VideoError` naming what is wrong."""
    path = Path(path)
    lay = _layout(path)
    s = lay.setup
    info = ClipInfo(str(path), "cine", lay.width, lay.height, lay.n_images, int(s.get("RealBPP") or lay.bits))
    rate = s.get("FrameRate") or s["FrameRate16"]
    k = _decimation(lay.times, float(rate))
    info.fps = rate / k
    info.source["fps"] = f"{path.name} FrameRate" + (
        f" {rate} / {k}: the clip holds every {_ordinal(k)} recorded frame (its timestamps)" if k > 1 else ""
    )
    if s.get("ShutterNs"):
        info.exposure_s, info.source["exposure_s"] = s["ShutterNs"] * 1e-9, "ShutterNs"
    elif s.get("Shutter"):
        info.exposure_s, info.source["exposure_s"] = s["Shutter"] * 1e-6, "Shutter (us)"
    info.trigger_frame, info.source["trigger_frame"] = 0, "FirstImageNo (images numbered from the trigger)"
    info.frame_numbers = lay.first_image_no + np.arange(lay.n_images, dtype=np.int64)
    info.source["frame_numbers"] = f"FirstImageNo {lay.first_image_no}"
    info.source["timestamps"] = "tagged block 1002, from TriggerTime" if lay.times is not None else "none in the file"
    return info


def cine_frames(info: ClipInfo) -> Iterator[tuple[int, float | None, np.ndarray]]:
    """Yield the images of a cine clip one at a time (uint8 or uint16, top row first) with their times."""
    path = Path(info.path)
    lay = _layout(path)
    dtype = np.uint8 if lay.bits == 8 else np.dtype("<u2")
    nbytes = lay.width * lay.height * lay.bits // 8
    data = np.memmap(path, dtype=np.uint8, mode="r")
    for k, ptr in enumerate(lay.pointers):
        if ptr + 8 > data.size:
            raise VideoError(
                f"{path}: frame {k}: the file ends at byte {data.size}, before its image at {ptr}: truncated"
            )
        annotation = int(data[ptr : ptr + 4].view("<u4")[0])
        start = ptr + annotation
        if annotation < 8 or start + nbytes > data.size:
            raise VideoError(
                f"{path}: frame {k}: the file ends at byte {data.size}, inside its image ({nbytes} bytes from "
                f"{start}): truncated"
            )
        frame = np.array(data[start : start + nbytes].view(dtype)).reshape(lay.height, lay.width)
        t = None if lay.times is None else float(lay.times[k])
        yield k, t, frame[::-1] if lay.bottom_up else frame
