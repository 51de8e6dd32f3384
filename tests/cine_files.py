"""Phantom ``.cine`` files written for the tests (tests/video/test_cine.py, bench/cine_pims_check.py).

Written from the public description of the format, Vision Research's "The Cine File Format"
(SDK release 640, 2007): everything little-endian and packed,

- CINEFILEHEADER (44 bytes at 0): ``Type`` "CI", ``Headersize``, ``Compression`` (0 grey or
  interpolated colour, 1 JPEG, 2 uninterpolated colour), ``Version``, ``FirstMovieImage``,
  ``TotalImageCount``, ``FirstImageNo`` (the first saved image's number counted from the
  trigger, image 0), ``ImageCount``, ``OffImageHeader``, ``OffSetup``, ``OffImageOffsets`` and
  ``TriggerTime`` (TIME64: whole seconds in the high 32 bits, fractions of 2**-32 s in the low);
- BITMAPINFOHEADER (40 bytes): a positive ``biHeight`` stores the rows bottom-up;
- SETUP (``Length`` bytes, said at byte 142; an older program's setup is shorter, the fields
  after its end absent): the fields set here at their byte offsets, the rest zero;
- the tagged information blocks right after the setup, each ``BlockSize`` (uint32, with its
  8-byte head), ``Type`` (uint16) and a uint16 read as "more blocks follow" (ballbat and pims
  both stop after a block where it is 0): 1002 one TIME64 per image, 1003 each image's
  exposure (uint32, in 2**-32 s);
- ``ImageCount`` 64-bit image offsets at ``OffImageOffsets``;
- at each offset the image's annotation: ``AnnotationSize`` (uint32, with itself and the
  ``ImageSize`` after the annotation), the annotation bytes, ``ImageSize`` (uint32), then the
  pixels.

Where the offsets come from: the header's, the bitmap header's and the SETUP fields ballbat reads
(``FrameRate16``, ``Length``, ``FrameRate``, ``Shutter``, ``CFA``, ``RealBPP``, ``ShutterNs``) are
the description's, as ``ballbat.video.cine`` has them (checked there on two real PCC files
before); ``ImWidth``, ``ImHeight``, ``SoftwareVersion`` and where an older program's setup ends
(:data:`SETUP_649`, :data:`SETUP_605`, :data:`SETUP_FULL`) were counted from pims 0.7's list of
the SETUP fields, which pims needs to read a file at all. No program's code was copied.
Deterministic: the same :class:`CineSpec` gives the same bytes (the SHA-256 sums in the tests
hold).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

#: The SETUP fields written: (byte offset, struct code), as in the format's description.
SETUP_FIELDS = {
    "FrameRate16": (0, "H"),
    "Shutter16": (2, "H"),  # us
    "Mark": (140, "2s"),
    "Length": (142, "H"),
    "ImWidth": (737, "H"),
    "ImHeight": (739, "H"),
    "FrameRate": (768, "I"),
    "Shutter": (772, "I"),  # us
    "SoftwareVersion": (800, "I"),
    "CFA": (808, "I"),
    "RealBPP": (896, "I"),
    "ShutterNs": (1568, "I"),
}
SETUP_FULL = 7240  # the whole SETUP as PCC 3.x writes it (pims 0.7's layout of it is as long)
SETUP_649 = 5732  # software 649's setup (PCC of 2008) ends after Hue
SETUP_605 = 1044  # software 605's ends after bStampTime: no ShutterNs (pims cannot read that: it needs ShutterNs)
TRIGGER_S = 1_700_000_000  # TriggerTime's seconds (2023-11-14 22:13:20 UTC)
TRIGGER_FRAC = 0x2345_6789  # and its fraction, in 2**-32 s


@dataclass(frozen=True)
class CineSpec:
    """What a written cine file holds."""

    width: int = 40
    height: int = 24
    bits: int = 16  # biBitCount: 8 or 16 grey (10/12 for a packed file, refused)
    real_bpp: int = 12
    n_images: int = 6
    first_image_no: int = -25
    frame_rate: int = 90000  # FrameRate: the recording's
    every: int = 1  # saved every k-th recorded frame (the timestamps step k frames)
    shutter_ns: int = 10_000
    setup_length: int = SETUP_FULL
    software_version: int = 781
    compression: int = 0
    cfa: int = 0
    bottom_up: bool = True
    annotation: bytes = b""  # the annotation's bytes between AnnotationSize and ImageSize
    time_block: bool = True  # write block 1002 (and 1003): pims needs both


def frames(spec: CineSpec) -> np.ndarray:
    """Return the images (n, height, width), top row first: a pattern that differs in every row, column and image."""
    k, y, x = np.ogrid[: spec.n_images, : spec.height, : spec.width]
    values = x * 37 + y * 101 + k * 997 + (x * y % 13) * 7
    dtype = np.uint8 if spec.bits == 8 else np.uint16
    return (values % (1 << spec.real_bpp)).astype(dtype)


def image_ticks(spec: CineSpec) -> list[int]:
    """Return each image's time from the trigger in 2**-32 s: (FirstImageNo + i) * every / FrameRate, rounded."""
    out = []
    for i in range(spec.n_images):
        num = (spec.first_image_no + i) * spec.every << 32
        out.append((2 * num + spec.frame_rate) // (2 * spec.frame_rate))  # round half up, exact integers
    return out


def _setup(spec: CineSpec) -> bytes:
    values = {
        "FrameRate16": min(spec.frame_rate, 0xFFFF),
        "Shutter16": min(round(spec.shutter_ns / 1000), 0xFFFF),
        "Mark": b"ST",
        "Length": spec.setup_length,
        "ImWidth": spec.width,
        "ImHeight": spec.height,
        "FrameRate": spec.frame_rate,
        "Shutter": round(spec.shutter_ns / 1000),
        "SoftwareVersion": spec.software_version,
        "CFA": spec.cfa,
        "RealBPP": spec.real_bpp,
        "ShutterNs": spec.shutter_ns,
    }
    raw = bytearray(spec.setup_length)
    for name, (pos, code) in SETUP_FIELDS.items():
        if pos + struct.calcsize(code) <= spec.setup_length:
            struct.pack_into("<" + code, raw, pos, values[name])
    return bytes(raw)


def _tagged_blocks(spec: CineSpec) -> bytes:
    if not spec.time_block:
        return b""
    n, trigger = spec.n_images, (TRIGGER_S << 32) + TRIGGER_FRAC
    times = struct.pack(f"<{n}Q", *(trigger + t for t in image_ticks(spec)))
    exposure = round(spec.shutter_ns * 1e-9 * 2**32)
    exposures = struct.pack(f"<{n}I", *([exposure] * n))
    return (
        struct.pack("<IHH", 8 + len(times), 1002, 1)
        + times
        + struct.pack("<IHH", 8 + len(exposures), 1003, 0)
        + exposures
    )


def _pixels(spec: CineSpec, image: np.ndarray) -> bytes:
    rows = image[::-1] if spec.bottom_up else image
    if spec.bits in (8, 16):
        return np.ascontiguousarray(rows).astype("<u2" if spec.bits == 16 else "u1").tobytes()
    return bytes(spec.width * spec.height * spec.bits // 8)  # packed: a size, the content never read


def cine_bytes(spec: CineSpec) -> bytes:
    """Return the whole file."""
    setup, blocks = _setup(spec), _tagged_blocks(spec)
    off_bi, off_setup = 44, 84
    off_ptr = off_setup + len(setup) + len(blocks)
    n, npx = spec.n_images, spec.width * spec.height
    image_size = npx * spec.bits // 8
    height = spec.height if spec.bottom_up else -spec.height
    header = struct.pack(
        "<2sHHHiIiIIIIQ",
        *(b"CI", 44, spec.compression, 1, spec.first_image_no, n, spec.first_image_no, n),
        *(off_bi, off_setup, off_ptr, (TRIGGER_S << 32) + TRIGGER_FRAC),
    )
    bitmap = struct.pack("<IiiHHIIiiII", 40, spec.width, height, 1, spec.bits, 0, image_size, 0, 0, 0, 0)
    images, at = [], off_ptr + 8 * n
    pointers = []
    for image in frames(spec):
        head = struct.pack("<I", 8 + len(spec.annotation)) + spec.annotation + struct.pack("<I", image_size)
        pointers.append(at)
        images.append(head + _pixels(spec, image))
        at += len(images[-1])
    return header + bitmap + setup + blocks + struct.pack(f"<{n}Q", *pointers) + b"".join(images)


def write_cine(path: Path, spec: CineSpec = CineSpec(), cut: int | None = None) -> Path:
    """Write the file (its first ``cut`` bytes where given: a truncated file) and return its path."""
    path.write_bytes(cine_bytes(spec)[:cut])
    return path


#: The files of the tests (and of bench/cine_pims_check.py, which had pims read them).
SPECS = {
    # 16-bit container, 12 effective bits; recorded at 90000 fps, saved every 10th: 9000 fps
    "every10th": CineSpec(n_images=15, first_image_no=-5417, every=10),
    # 8-bit, a longer annotation before each image, images after the trigger
    "grey8": CineSpec(
        bits=8,
        real_bpp=8,
        width=33,
        height=20,
        first_image_no=3,
        frame_rate=2000,
        shutter_ns=250_000,
        annotation=b"ballbat test\x00\x00\x00\x00",
    ),
    # an older PCC's file (software 649, 2008): its shorter setup, 14 effective bits
    "legacy": CineSpec(
        real_bpp=14,
        n_images=5,
        first_image_no=-7722,
        frame_rate=35087,
        shutter_ns=1000,
        setup_length=SETUP_649,
        software_version=649,
    ),
}


def spec(name: str, **changes) -> CineSpec:
    """Return one of :data:`SPECS`, changed."""
    return replace(SPECS[name], **changes)
