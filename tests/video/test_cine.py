"""Phantom .cine clips (ballbat.video.cine; docs/video.md): files written by the tests' own writer, checked by pims.

The files are written by ``tests/cine_files.py`` from the format's public description. So that
the writer and the reader cannot share one misreading of the format, the reference values are
pims 0.7's (``pims.Cine``, an independent reader, in a venv of its own outside this project):
``bench/cine_pims_check.py`` wrote the files of ``cine_files.SPECS`` and printed what pims read
of them (run 2026-11-27, pims 0.7 and numpy 2.4.6). Kept here: the SHA-256 of some images (uint16
little-endian, top row first), each image's time from the trigger (``get_time_to_trigger``),
the mean frame rate from the timestamps (``get_frame_rate_avg``), the setup's frame rate,
exposure and ``RealBPP``. pims' times are seconds since 1970 as floats, so rounded to 2**-22 s
(0.24 us): they agree with ballbat's to that. What pims cannot read (top-down rows, no tagged
blocks, a setup without ``ShutterNs``, the refused kinds) is checked against what it read of the
files it can.
"""

from __future__ import annotations

import hashlib
import struct
from pathlib import Path

import numpy as np
import pytest
from cine_files import SETUP_605, SPECS, frames, image_ticks, spec, write_cine

from ballbat.video.io import VideoError, open_clip

#: pims' time resolution here: seconds since 1970 (about 1.7e9) as a float
PIMS_TIME_ABS = 2.0**-22

#: pims 0.7 on every10th.cine: images 0, 1 and 14 (SHA-256) and their times from the trigger (s).
PIMS_EVERY10TH = {
    0: ("a1d17668780a7be3934257c8d23b6a3590b62d600c2159b1514b89a4d6e93fce", -0.60188889503479),
    1: ("33e24aaedc4a92953489ccd0a4d240321a20fa2ba7ba5c3be17a145b7dfc2a64", -0.6017777919769287),
    14: ("e40b9e479a3baa59073ca0e2b91da58dc6041dd1ca7fb8d18d2801c61fdd68b3", -0.6003334522247314),
}
#: pims 0.7 on grey8.cine: images 0, 1 and 5.
PIMS_GREY8 = {
    0: ("44532300ac8ce912cfc36d772c1bbdff69a8a2aa0d2272294fd69f227e7a3682", 0.0014998912811279297),
    1: ("f54a3d26d4493ba9fdb0fe4f430c1ec0b4cfac4f446b8e2c1a6a00ba230ce452", 0.0019998550415039062),
    5: ("fd6d0ed8c37260a7ec0eeeac60365bfe6afd58b79ef79616b38ac53b792c69ed", 0.003999948501586914),
}
#: pims 0.7 on legacy.cine: images 0, 1 and 4.
PIMS_LEGACY = {
    0: ("a1d17668780a7be3934257c8d23b6a3590b62d600c2159b1514b89a4d6e93fce", -0.22008156776428223),
    1: ("8a0b96be9ae283c00cadeb53a996b7b90938afcf6b38d3f6f3ca7855397a0e8b", -0.22005295753479004),
    4: ("d22b277e0cbc070956c1d11296f72ce3a62dad76efe0c76368d6d413c353df89", -0.21996760368347168),
}
#: pims 0.7's mean frame rate from the timestamps (its setup's FrameRate: 90000, 2000, 35087)
PIMS_RATE_AVG = {"every10th": 9000.652360515025, "grey8": 1999.9542974143005, "legacy": 35099.392717086834}


def _sha(frame: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(frame).astype("<u2").tobytes()).hexdigest()


def _read(path: Path) -> tuple[list[float | None], list[np.ndarray]]:
    stream = list(open_clip(path).frames())
    assert [k for k, _, _ in stream] == list(range(len(stream)))
    return [t for _, t, _ in stream], [a for _, _, a in stream]


def _agrees_with_pims(path: Path, expected: dict[int, tuple[str, float]], dtype) -> list[np.ndarray]:
    times, images = _read(path)
    assert {k: _sha(images[k]) for k in expected} == {k: v[0] for k, v in expected.items()}
    for k, (_, t) in expected.items():
        assert times[k] == pytest.approx(t, abs=PIMS_TIME_ABS)
    assert all(a.dtype == dtype for a in images)
    return images


def test_a_clip_saved_every_10th_frame_reads_as_pims_reads_it_at_its_true_rate(tmp_path):
    """every10th: 40 x 24, 16-bit container with 12 effective bits, 15 images recorded at 90000 fps
    and saved every 10th (as PCC's decimation at saving writes them: FrameRate stays 90000,
    the timestamps step 10 frames), FirstImageNo -5417, ShutterNs 10000 (pims: 10000).
    """
    path = write_cine(tmp_path / "every10th.cine", SPECS["every10th"])
    info = open_clip(path).info
    assert (info.width, info.height, info.n_frames, info.bit_depth) == (40, 24, 15, 12)  # pims' real_bpp 12
    assert info.fps == 9000.0 and "FrameRate 90000 / 10" in info.source["fps"]
    assert "every 10th recorded frame" in info.source["fps"]
    assert info.fps == pytest.approx(PIMS_RATE_AVG["every10th"], rel=1e-3)
    assert info.exposure_s == pytest.approx(10e-6) and info.source["exposure_s"] == "ShutterNs"
    assert info.trigger_frame == 0 and info.frame_numbers[[0, -1]].tolist() == [-5417, -5403]
    assert info.source["timestamps"] == "tagged block 1002, from TriggerTime"
    images = _agrees_with_pims(path, PIMS_EVERY10TH, np.uint16)
    assert np.array_equal(np.stack(images), frames(SPECS["every10th"]))  # every image, as written
    # each time on the 9000 fps grid: the tracker's check passes
    times = np.array(_read(path)[0])
    assert np.max(np.abs((times - times[0]) * info.fps - np.arange(15))) < 0.25


def test_an_8_bit_clip_after_the_trigger_with_a_longer_annotation(tmp_path):
    """grey8: 33 x 20, 8 bit, 6 images from image 3 after the trigger at 2000 fps, 250 us, each
    image's annotation 24 bytes (16 of text): pims reads the same images and times.
    """
    path = write_cine(tmp_path / "grey8.cine", SPECS["grey8"])
    info = open_clip(path).info
    assert (info.width, info.height, info.n_frames, info.bit_depth, info.fps) == (33, 20, 6, 8, 2000.0)
    assert info.source["fps"] == "grey8.cine FrameRate"  # no decimation
    assert info.fps == pytest.approx(PIMS_RATE_AVG["grey8"], rel=1e-3)
    assert info.exposure_s == pytest.approx(250e-6) and info.frame_numbers.tolist() == [3, 4, 5, 6, 7, 8]
    images = _agrees_with_pims(path, PIMS_GREY8, np.uint8)
    assert np.array_equal(np.stack(images), frames(SPECS["grey8"]))


def test_an_older_file_and_its_truncation(tmp_path):
    """legacy: an older PCC's file (software 649, its setup 5732 bytes), 40 x 24, 14 effective
    bits, 5 images at 35087 fps, 1 us, FirstImageNo -7722; then the same file cut inside its 3rd
    image's pixels, and before its 3rd image: the 3rd is named as missing.
    """
    path = write_cine(tmp_path / "legacy.cine", SPECS["legacy"])
    info = open_clip(path).info
    assert (info.width, info.height, info.n_frames, info.bit_depth, info.fps) == (40, 24, 5, 14, 35087.0)
    assert info.fps == pytest.approx(PIMS_RATE_AVG["legacy"], rel=1e-3)
    assert info.exposure_s == pytest.approx(1e-6) and info.frame_numbers[0] == -7722
    _agrees_with_pims(path, PIMS_LEGACY, np.uint16)
    size = path.stat().st_size
    image = 8 + 40 * 24 * 2  # the annotation (8 bytes) and the pixels of one image
    for cut, message in ((size - 2 * image - 100, "inside its image"), (size - 3 * image + 4, "before its image")):
        stream = open_clip(write_cine(tmp_path / "legacy_cut.cine", SPECS["legacy"], cut=cut)).frames()
        for k in (0, 1):
            _, t, a = next(stream)
            assert (_sha(a), pytest.approx(t, abs=PIMS_TIME_ABS)) == PIMS_LEGACY[k]
        with pytest.raises(VideoError, match=rf"legacy_cut\.cine: frame 2: the file ends .*{message}.*truncated"):
            next(stream)


def test_rows_stored_top_down_read_as_the_bottom_up_file_pims_read(tmp_path):
    """A negative biHeight stores the rows top-down (pims cannot read that: it takes every file as bottom-up)."""
    up = _read(write_cine(tmp_path / "up.cine", SPECS["every10th"]))
    down = _read(write_cine(tmp_path / "down.cine", spec("every10th", bottom_up=False)))
    assert up[0] == down[0] and all(np.array_equal(a, b) for a, b in zip(up[1], down[1], strict=True))
    assert _sha(down[1][14]) == PIMS_EVERY10TH[14][0]


def test_what_pims_cannot_read_the_setup_and_blocks_an_old_file_may_lack(tmp_path):
    """A setup without ShutterNs (software 605: pims 0.7 stops, it needs ShutterNs): the exposure from
    Shutter, in us (the field pims read as 10 and 1 in every10th and legacy); a file without
    tagged blocks (pims stops too): no times, and the setup's FrameRate as it is; a setup ending
    before FrameRate: FrameRate16, no exposure, the container's bits.
    """
    old = open_clip(write_cine(tmp_path / "old.cine", spec("legacy", setup_length=SETUP_605, software_version=605)))
    assert old.info.exposure_s == pytest.approx(1e-6) and old.info.source["exposure_s"] == "Shutter (us)"
    assert old.info.bit_depth == 14 and old.info.fps == 35087.0
    bare = open_clip(write_cine(tmp_path / "bare.cine", spec("every10th", time_block=False)))
    assert bare.info.fps == 90000.0 and bare.info.source["timestamps"] == "none in the file"
    assert [t for _, t, _ in bare.frames()] == [None] * 15
    oldest = open_clip(write_cine(tmp_path / "oldest.cine", spec("grey8", setup_length=768, real_bpp=7)))
    assert (oldest.info.fps, oldest.info.exposure_s, oldest.info.bit_depth) == (2000.0, None, 8)
    assert oldest.info.source["fps"] == "oldest.cine FrameRate"


def test_times_keep_their_precision_at_a_million_frames_per_second(tmp_path):
    """TriggerTime is 1.7e9 s since 1970: each image's time is taken from it as integers first, so the
    times keep TIME64's 2**-32 s (the tracker checks each to a quarter frame: 0.14 us at 1.75 Mfps).
    Before, each time was a float of seconds since 1970 first (as pims' still are), 2**-22 s apart:
    steps of 0.83-1.25 frames at 1.75 Mfps.
    """
    fast = spec("every10th", n_images=40, first_image_no=-20, frame_rate=1_750_000, every=1, shutter_ns=300)
    times = np.array(_read(write_cine(tmp_path / "fast.cine", fast))[0])
    exact = np.array(image_ticks(fast)) / 2.0**32
    assert np.max(np.abs(times - exact)) < 1e-15
    assert np.max(np.abs(np.diff(times) * 1_750_000 - 1)) < 1e-3
    half = open_clip(write_cine(tmp_path / "half.cine", spec("every10th", frame_rate=1_000_000, every=2)))
    assert half.info.fps == 500_000.0 and "every 2nd recorded frame" in half.info.source["fps"]


def _edited(tmp_path: Path, name: str, edits: dict[int, bytes], cut: int | None = None, **changes) -> Path:
    raw = bytearray(write_cine(tmp_path / name, spec("every10th", **changes), cut=cut).read_bytes())
    for at, value in edits.items():
        raw[at : at + len(value)] = value
    (tmp_path / name).write_bytes(bytes(raw))
    return tmp_path / name


@pytest.mark.parametrize(
    ("name", "changes", "edits", "message"),
    [
        ("bayer.cine", {"compression": 2}, {}, r"bayer\.cine: a raw colour \(uninterpolated Bayer\) clip"),
        ("jpeg.cine", {"compression": 1}, {}, r"jpeg\.cine: a JPEG-compressed clip"),
        ("colour.cine", {"cfa": 3}, {}, r"colour\.cine: a colour clip \(CFA 3"),
        ("rgb.cine", {"bits": 24}, {}, r"rgb\.cine: a colour clip \(CFA 0, 24 bits\)"),
        ("packed12.cine", {"bits": 12}, {}, r"packed12\.cine: 12-bit pixels.*packed 10/12-bit is not"),
        ("packed10.cine", {"bits": 10}, {}, r"packed10\.cine: 10-bit pixels.*packed 10/12-bit is not"),
        # a 16-bit container whose images hold 12 bits a pixel (biSizeImage): packed all the same
        ("packed16.cine", {}, {44 + 20: struct.pack("<I", 40 * 24 * 12 // 8)}, r"packed16\.cine: 16-bit pixels, .*"),
        ("other.cine", {}, {0: b"RI"}, r"other\.cine: not a Phantom cine file"),
    ],
)
def test_clips_it_cannot_read_are_refused_with_the_reason(tmp_path, name, changes, edits, message):
    with pytest.raises(VideoError, match=message):
        open_clip(_edited(tmp_path, name, edits, **changes))


def test_a_truncated_header_is_named(tmp_path):
    with pytest.raises(VideoError, match=r"short\.cine: the file ends inside its .*truncated"):
        open_clip(_edited(tmp_path, "short.cine", {}, cut=200))
