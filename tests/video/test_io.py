"""Clip files: writers and streamed readers (ballbat.video.io, ballbat.video.mraw; docs/video.md)."""

from __future__ import annotations

import types
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from video_clips import M_PER_PX, PLAIN, spin_truth

from ballbat.video.io import VideoError, open_clip, write_clip
from ballbat.video.render import render_frames

DATA = Path(__file__).parents[1] / "data" / "video"


def _frames(bits: int = 8, n: int = 4) -> list[np.ndarray]:
    return list(render_frames(spin_truth(n=n), replace(PLAIN, bit_depth=bits), M_PER_PX))


@pytest.mark.parametrize(("name", "bits"), [("c.tif", 8), ("c.tiff", 16), ("c.mkv", 8), ("c.mkv", 12)])
def test_lossless_files_give_back_every_frame_and_their_settings(tmp_path, name, bits):
    frames = _frames(bits)
    path = write_clip(
        tmp_path / name, iter(frames), 3000.0, exposure_s=5e-5, trigger_frame=2, frame_numbers=np.arange(40, 44)
    )
    clip = open_clip(path)
    info = clip.info
    assert (info.width, info.height, info.fps, info.exposure_s, info.trigger_frame) == (240, 160, 3000.0, 5e-5, 2)
    assert info.bit_depth == (8 if bits == 8 else 16)
    assert info.frame_numbers.tolist() == [40, 41, 42, 43]
    stream = clip.frames()
    assert isinstance(stream, types.GeneratorType)  # streamed, not read whole
    got = list(stream)
    assert [k for k, _, _ in got] == [0, 1, 2, 3]
    for (_, _, a), b in zip(got, frames, strict=True):
        np.testing.assert_array_equal(a, b)


def test_h264_is_close_and_timed_by_its_packets(tmp_path):
    frames = _frames(8, n=6)
    clip = open_clip(write_clip(tmp_path / "c.mp4", iter(frames), 1000.0, crf=18))
    assert clip.info.fps == 1000.0 and clip.info.format == "h264" and clip.info.n_frames == 6
    got = list(clip.frames())
    times = np.array([t for _, t, _ in got])
    np.testing.assert_allclose(np.diff(times), 1e-3, rtol=1e-9)
    err = [np.abs(a.astype(int) - b.astype(int)).mean() for (_, _, a), b in zip(got, frames, strict=True)]
    assert max(err) < 2.0  # lossy but close (grey levels)
    assert max(err) > 0.0


def test_matroska_times_are_left_out_when_coarser_than_the_frames(tmp_path):
    """Matroska counts 1 ms: at 3000 fps its timestamps cannot tell frames apart, so none are given."""
    clip = open_clip(write_clip(tmp_path / "c.mkv", iter(_frames(8, n=2)), 3000.0))
    assert clip.info.source["time_base"] == "1/1000"
    assert [t for _, t, _ in clip.frames()] == [None, None]


def test_a_failed_write_leaves_nothing(tmp_path):
    def broken():
        yield from _frames(8, n=2)
        raise RuntimeError("camera unplugged")

    for name in ("c.tif", "c.mkv"):
        with pytest.raises(RuntimeError, match="unplugged"):
            write_clip(tmp_path / name, broken(), 1000.0)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(VideoError, match=r"c\.gif: unknown clip extension"):
        write_clip(tmp_path / "c.gif", iter(_frames(8, n=1)), 1000.0)


def test_photron_16_bit_sample_settings_and_frames():
    """beam.cihx/.mraw: a FASTCAM SA-Z recording saved by Photron's PFV (pyMRAW's sample)."""
    clip = open_clip(DATA / "beam.cihx")
    info = clip.info
    assert (info.width, info.height, info.n_frames, info.fps) == (1024, 80, 4, 50000.0)
    assert info.exposure_s == pytest.approx(5e-6) and info.bit_depth == 12
    assert info.frame_numbers.tolist() == [0, 1, 2, 3] and info.trigger_frame == 0
    frames = [a for _, _, a in clip.frames()]
    assert len(frames) == 4 and all(a.dtype == np.uint16 and a.shape == (80, 1024) for a in frames)
    assert max(int(a.max()) for a in frames) <= 4095  # 12 effective bits, the lower ones
    assert 0 < np.mean(np.abs(frames[1].astype(int) - frames[0].astype(int))) < 200  # a scene, not noise


def test_photron_12_bit_packed_sample_and_its_truncation():
    """ball_12bit: a Nova S16 clip of a ball, 12-bit packed; the file here holds 2 of its 15 frames."""
    clip = open_clip(DATA / "ball_12bit_2frames.cihx")
    info = clip.info
    assert (info.width, info.height, info.n_frames, info.fps) == (384, 384, 15, 30000.0)
    assert info.exposure_s == pytest.approx(20e-6)
    assert info.frame_numbers[:2].tolist() == [52, 53]  # startFrame: numbered from the trigger
    stream = clip.frames()
    _, _, first = next(stream)
    # the ball, backlit: a dark disc round (170, 110) on a bright background
    assert first[110, 150] < 0.3 * np.median(first) and np.median(first) > 3000
    next(stream)
    with pytest.raises(VideoError, match=r"ball_12bit_2frames\.mraw: frame 2: the file ends .*truncated"):
        next(stream)


def test_unknown_or_missing_files_are_named(tmp_path):
    with pytest.raises(VideoError, match="file not found"):
        open_clip(tmp_path / "none.mp4")
    (tmp_path / "c.xyz").write_bytes(b"0")
    with pytest.raises(VideoError, match=r"c\.xyz: unknown clip extension"):
        open_clip(tmp_path / "c.xyz")
    (tmp_path / "junk.mp4").write_bytes(b"not a video at all" * 10)
    with pytest.raises(VideoError, match=r"junk\.mp4: frame 0: cannot be opened as video"):
        open_clip(tmp_path / "junk.mp4")
    (tmp_path / "lone.cihx").write_bytes((DATA / "beam.cihx").read_bytes())
    with pytest.raises(VideoError, match=r"lone\.cihx: its frames lone\.mraw are not beside it"):
        open_clip(tmp_path / "lone.cihx")


def _stream_facts(frames, duration_us, rate, time_base):
    """Return ``_av_facts`` of a container whose one stream says these (the numbers a phone's clip has)."""
    from fractions import Fraction

    from ballbat.video.io import _av_facts

    s = types.SimpleNamespace(
        format=types.SimpleNamespace(name="yuv420p"),
        codec_context=types.SimpleNamespace(name="h264"),
        average_rate=Fraction(rate),
        guessed_rate=None,
        frames=frames,
        width=550,
        height=310,
        time_base=Fraction(time_base),
    )
    c = types.SimpleNamespace(streams=types.SimpleNamespace(video=[s]), duration=duration_us, metadata={})
    return _av_facts(c, Path("clip.mp4"))


def test_a_trimmed_clip_counts_the_frames_it_shows():
    """A phone's trimmed clip stores 2057 frames, 212 of them before its edit list's start: 1843 shown, 30.73 s."""
    f = _stream_facts(2057, 30_730_998, "718080/11971", "1/15360")
    assert (f["n"], f["slack"]) == (1843, 1)
    f = _stream_facts(1537, 25_618_718, "5930/99", "1/11860")  # two frames stored past the end
    assert (f["n"], f["slack"]) == (1535, 1)
    f = _stream_facts(1536, 25_618_718, "5930/99", "1/11860")  # a frame more than the duration: the count stands
    assert (f["n"], f["slack"]) == (1536, 0)
    f = _stream_facts(0, 2_000_000, "60", "1/1000")  # no count: the duration's, to its time base
    assert (f["n"], f["slack"]) == (120, 1)
