"""Photron MRAW clips: the header (``.cihx`` XML or ``.cih`` text) and the raw frames (``.mraw``), streamed.

Read here rather than with pyMRAW: pyMRAW needs numba (with llvmlite, about 210 MB
installed) and unpacks a 12-bit clip whole into memory; this reads one frame at a time from
a memory map (8 and 16 bit as they are, 12-bit packed unpacked per frame). What is read
(docs/video.md): the size, the colour type and bits (``Mono``/``Raw`` grey only: a colour or
Bayer clip is refused), the effective bits, the frame rate (``recordRate``), the exposure
(``shutterSpeedNsec``, else 1 / ``shutterSpeed``), the number of frames (``totalFrame``) and
the first frame's number relative to the trigger (``startFrame``; the trigger is frame 0).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from .clip import ClipInfo, VideoError

MRAW_EXT = (".cihx", ".cih")


def _cihx(path: Path) -> dict[str, str]:
    raw = path.read_bytes()
    start, end = raw.find(b"<cih>"), raw.rfind(b"</cih>")
    if start < 0 or end < 0:
        raise VideoError(f"{path}: no <cih> header in the file")
    try:
        root = ET.fromstring(raw[start : end + 6].decode("utf-8", "replace"))
    except ET.ParseError as exc:
        raise VideoError(f"{path}: the <cih> header is not XML ({exc})") from None
    keys = {
        "width": "imageDataInfo/resolution/width",
        "height": "imageDataInfo/resolution/height",
        "type": "imageDataInfo/colorInfo/type",
        "bit": "imageDataInfo/colorInfo/bit",
        "effective": "imageDataInfo/effectiveBit/depth",
        "side": "imageDataInfo/effectiveBit/side",
        "format": "imageFileInfo/fileFormat",
        "frames": "frameInfo/totalFrame",
        "start": "frameInfo/startFrame",
        "fps": "recordInfo/recordRate",
        "shutter_ns": "recordInfo/shutterSpeedNsec",
        "shutter": "recordInfo/shutterSpeed",
    }
    return {k: root.findtext(v).strip() for k, v in keys.items() if root.findtext(v) is not None}


def _cih(path: Path) -> dict[str, str]:
    keys = {
        "Image Width": "width",
        "Image Height": "height",
        "Color Type": "type",
        "Color Bit": "bit",
        "EffectiveBit Depth": "effective",
        "EffectiveBit Side": "side",
        "File Format": "format",
        "Total Frame": "frames",
        "Start Frame": "start",
        "Record Rate(fps)": "fps",
        "Shutter Speed(s)": "shutter_s",
    }
    out = {}
    for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
        key, sep, val = line.partition(" : ")
        if sep and key.strip() in keys:
            out[keys[key.strip()]] = val.strip()
    return out


def _number(h: dict, key: str, path: Path, kind=int):
    try:
        return kind(float(h[key])) if kind is int else kind(h[key])
    except (KeyError, ValueError):
        raise VideoError(f"{path}: header has no valid {key} ({h.get(key)!r})") from None


def mraw_info(path: str | Path) -> ClipInfo:
    """Read a Photron header and check its raw file; a :class:`VideoError` naming what is wrong."""
    path = Path(path)
    h = _cihx(path) if path.suffix.lower() == ".cihx" else _cih(path)
    raw = path.with_suffix(".mraw")
    if not raw.is_file():
        raise VideoError(f"{path}: its frames {raw.name} are not beside it")
    if h.get("format", "mraw").lower() != "mraw":
        raise VideoError(f"{path}: file format {h['format']!r}; only MRAW is read (save the clip as MRAW in PFV)")
    if h.get("type", "Mono").lower() not in ("mono", "raw"):
        raise VideoError(f"{path}: colour type {h['type']!r}; only grey (Mono/Raw) clips are read")
    width, height, bit = (_number(h, k, path) for k in ("width", "height", "bit"))
    if bit not in (8, 12, 16):
        raise VideoError(f"{path}: {bit}-bit pixels; 8, 12 (packed) or 16 are read")
    info = ClipInfo(str(path), "mraw", width, height, _number(h, "frames", path), int(h.get("effective", bit)))
    info.fps = _number(h, "fps", path, float)
    info.source["fps"] = f"{path.name} recordRate"
    if "shutter_ns" in h:
        info.exposure_s, info.source["exposure_s"] = _number(h, "shutter_ns", path) * 1e-9, "shutterSpeedNsec"
    elif "shutter" in h:
        info.exposure_s, info.source["exposure_s"] = 1.0 / _number(h, "shutter", path, float), "1 / shutterSpeed"
    elif "shutter_s" in h:
        info.exposure_s, info.source["exposure_s"] = _number(h, "shutter_s", path, float), "Shutter Speed(s)"
    start = _number(h, "start", path) if "start" in h else 0
    info.trigger_frame, info.source["trigger_frame"] = 0, "startFrame (frames numbered from the trigger)"
    info.frame_numbers = start + np.arange(info.n_frames, dtype=np.int64)
    info.source["frame_numbers"] = f"startFrame {start}"
    info.source["container_bits"] = str(bit)
    return info


def mraw_frames(info: ClipInfo) -> Iterator[tuple[int, None, np.ndarray]]:
    """Yield the frames of an MRAW clip one at a time (uint8 or uint16)."""
    path = Path(info.path)
    raw = path.with_suffix(".mraw")
    bit = int(info.source["container_bits"])
    npx = info.width * info.height
    nbytes = npx * bit // 8
    data = np.memmap(raw, dtype=np.uint8, mode="r")
    for k in range(info.n_frames):
        chunk = data[k * nbytes : (k + 1) * nbytes]
        if chunk.size < nbytes:
            raise VideoError(
                f"{raw}: frame {k}: the file ends ({data.size} bytes hold {data.size // nbytes} whole frames "
                f"of the {info.n_frames} its header says): truncated"
            )
        if bit == 8:
            frame = np.array(chunk)
        elif bit == 16:
            frame = np.array(chunk.view("<u2"))
        else:  # 12-bit packed: 3 bytes, 2 pixels, high nibble first
            b = chunk.reshape(-1, 3).astype(np.uint16)
            frame = np.empty(npx, np.uint16)
            frame[0::2] = (b[:, 0] << 4) | (b[:, 1] >> 4)
            frame[1::2] = ((b[:, 1] & 0xF) << 8) | b[:, 2]
        yield k, None, frame.reshape(info.height, info.width)
