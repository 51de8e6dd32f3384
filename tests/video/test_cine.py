"""Phantom .cine clips (ballbat.video.cine; docs/video.md): two files recorded by Phantom cameras.

The reference values are pims 0.7's (``pims.Cine``, an independent reader of the same files,
run once outside this project): the SHA-256 of each image as uint16 little-endian, top row
first, and each image's time from the trigger (``get_time_to_trigger``).
"""

from __future__ import annotations

import hashlib
import struct
from pathlib import Path

import numpy as np
import pytest

from ballbat.video.io import VideoError, open_clip

DATA = Path(__file__).parents[1] / "data" / "video"

#: pims 0.7 on cine_781.cine: images 0, 1 and 14 (SHA-256) and their times from the trigger (s).
PIMS_781 = {
    0: ("2ea60039159e914952aca73bdc8ded16796e927a17ef9aea663b5dc3069d9a6e", -0.6016726493835449),
    1: ("343f3c38f301344f768924992f9a92f438a75fca456137c9331d5af682399cb5", -0.6015617847442627),
    14: ("f476e8ff34cb045d1493925479518ff025dd5350630bd5d6f18d5357fa47b93c", -0.6001176834106445),
}
#: pims 0.7 on the whole cine_legacy.cine: images 0 and 1.
PIMS_LEGACY = {
    0: ("7cc324dcb219d0ee6fa62a5828ab0e51c6d1f40847015d0389d85f4b104da4a5", -0.2200479507446289),
    1: ("b74dd91b1d332e0da7b35c271692d637eb709141151f40c2c93902a15d2ce4ad", -0.22002005577087402),
}


def _sha(frame: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(frame).astype("<u2").tobytes()).hexdigest()


def test_a_clip_saved_every_10th_frame_reads_as_pims_reads_it_at_its_true_rate():
    """cine_781: Phantom Camera Control 3.3.781, 256 x 256, 15 images. Its author's note (pims'
    tests): "Recording fps 90,000, with decimation 10 at saving (actual fps 9,000)".
    """
    clip = open_clip(DATA / "cine_781.cine")
    info = clip.info
    assert (info.width, info.height, info.n_frames, info.bit_depth) == (256, 256, 15, 12)
    assert info.fps == 9000.0 and "FrameRate 90000 / 10" in info.source["fps"]
    assert info.exposure_s == pytest.approx(10e-6) and info.source["exposure_s"] == "ShutterNs"
    assert info.trigger_frame == 0 and info.frame_numbers[[0, -1]].tolist() == [-5417, -5403]
    seen = {k: (_sha(a), t) for k, t, a in clip.frames() if k in PIMS_781}
    assert {k: v[0] for k, v in seen.items()} == {k: v[0] for k, v in PIMS_781.items()}
    for k, (_, t) in seen.items():
        assert t == pytest.approx(PIMS_781[k][1], abs=1e-9)
    # each time on the 9000 fps grid: the tracker's check passes
    times = np.array([t for _, t, _ in clip.frames()])
    assert np.max(np.abs((times - times[0]) * info.fps - np.arange(15))) < 0.25


def test_an_older_file_and_its_truncation():
    """cine_legacy (pims' sample, PCC 649, 2008): 128 x 128, 97 images at 35087 fps; the file here is
    cut after its 2nd image, so the 3rd is named as missing.
    """
    clip = open_clip(DATA / "cine_legacy_2frames.cine")
    info = clip.info
    assert (info.width, info.height, info.n_frames, info.bit_depth, info.fps) == (128, 128, 97, 14, 35087.0)
    assert info.exposure_s == pytest.approx(1e-6) and info.frame_numbers[0] == -7722
    stream = clip.frames()
    for k in (0, 1):
        _, t, a = next(stream)
        assert a.dtype == np.uint16 and (_sha(a), pytest.approx(t, abs=1e-9)) == (
            PIMS_LEGACY[k][0],
            PIMS_LEGACY[k][1],
        )
    with pytest.raises(VideoError, match=r"cine_legacy_2frames\.cine: frame 2: the file ends .*truncated"):
        next(stream)


def _edited(tmp_path: Path, name: str, edits: dict[int, bytes], cut: int | None = None) -> Path:
    raw = bytearray((DATA / "cine_781.cine").read_bytes()[:cut])
    for at, value in edits.items():
        raw[at : at + len(value)] = value
    path = tmp_path / name
    path.write_bytes(bytes(raw))
    return path


@pytest.mark.parametrize(
    ("name", "edits", "message"),
    [
        ("bayer.cine", {4: struct.pack("<H", 2)}, r"bayer\.cine: a raw colour \(uninterpolated Bayer\) clip"),
        ("jpeg.cine", {4: struct.pack("<H", 1)}, r"jpeg\.cine: a JPEG-compressed clip"),
        ("colour.cine", {84 + 808: struct.pack("<I", 3)}, r"colour\.cine: a colour clip \(CFA 3"),
        ("packed.cine", {44 + 14: struct.pack("<H", 12)}, r"packed\.cine: 12-bit pixels.*packed 10/12-bit is not"),
        ("other.cine", {0: b"RI"}, r"other\.cine: not a Phantom cine file"),
    ],
)
def test_clips_it_cannot_read_are_refused_with_the_reason(tmp_path, name, edits, message):
    with pytest.raises(VideoError, match=message):
        open_clip(_edited(tmp_path, name, edits))


def test_a_truncated_header_is_named(tmp_path):
    with pytest.raises(VideoError, match=r"short\.cine: the file ends inside its .*truncated"):
        open_clip(_edited(tmp_path, "short.cine", {}, cut=200))
