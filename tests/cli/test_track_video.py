"""Bad clips (docs/video.md): each stops `ballbat track-video`, naming the file and the frame; nothing written."""

from __future__ import annotations

import fractions
import shutil
from pathlib import Path

import av
import numpy as np
import pytest
import yaml
from video_clips import M_PER_PX, PLAIN, RADIUS_PX, spin_truth
from video_toss import TOSS_R, toss_clip

from ballbat.cli import main
from ballbat.video.io import write_clip
from ballbat.video.render import render_frames
from ballbat.video.track import TrackOptions, track_clip

DATA = Path(__file__).parents[1] / "data" / "video"


def _run(tmp_path, capsys, *clips):
    out = tmp_path / "out" / "tracks.csv"
    radii = f"{RADIUS_PX},{RADIUS_PX}"
    code = main(["track-video", *map(str, clips), "--ball-radius-px", radii, "-o", str(out), "--parents"])
    err = capsys.readouterr().err
    return code, err, out


def _good(tmp_path, name="W01_spin.tif", truth=None):
    truth = truth or spin_truth(n=3)
    return write_clip(tmp_path / name, render_frames(truth, PLAIN, M_PER_PX), truth.fps, frame_numbers=truth.frames)


def _nothing_written(out: Path) -> bool:
    return not out.parent.exists() or list(out.parent.iterdir()) == []


def test_a_good_clip_is_written_with_its_quality_table(tmp_path, capsys):
    code, err, out = _run(tmp_path, capsys, _good(tmp_path))
    assert code == 0, err
    assert out.read_text().startswith("impact_id,camera,point,frame,x_px,y_px\nW01,spin,ball,100,")
    assert (out.parent / "tracks.quality.csv").read_text().splitlines()[0].endswith("residual_px,contrast,left_out")


def test_a_truncated_clip(tmp_path, capsys):
    for ext in ("cihx", "mraw"):
        shutil.copy(DATA / f"ball_12bit_2frames.{ext}", tmp_path / f"W01_spin.{ext}")
    code, err, out = _run(tmp_path, capsys, _good(tmp_path, "W01_swing.tif"), tmp_path / "W01_spin.cihx")
    assert code == 1 and _nothing_written(out)
    assert "W01_spin.mraw: frame 2: the file ends" in err and "nothing written" in err


def test_a_corrupt_clip(tmp_path, capsys):
    good = _good(tmp_path, "W01_spin.mkv")
    data = bytearray(good.read_bytes())
    data[len(data) // 2 :] = bytes(len(data) - len(data) // 2)  # the second half zeroed
    good.write_bytes(bytes(data))
    code, err, out = _run(tmp_path, capsys, good)
    assert code == 1 and _nothing_written(out)
    assert "W01_spin.mkv: frame 2: the stream ends after 2 frames, its header says 3: truncated or corrupt" in err


def test_an_unknown_codec(tmp_path, capsys):
    good = _good(tmp_path, "W01_spin.mkv")
    good.write_bytes(good.read_bytes().replace(b"V_FFV1", b"V_QQQQ", 1))  # a codec id no decoder knows
    code, err, out = _run(tmp_path, capsys, good)
    assert code == 1 and _nothing_written(out)
    assert "W01_spin.mkv: frame 0:" in err


def test_a_clip_with_no_ball(tmp_path, capsys):
    truth = spin_truth(n=3)
    truth.x["ball"][:] = np.nan
    code, err, out = _run(tmp_path, capsys, _good(tmp_path, truth=truth))
    assert code == 1 and _nothing_written(out)
    assert "W01_spin.tif: frame 100: no ball found; the ball is found in none of its 3 frames" in err


def test_a_clip_with_two_balls(tmp_path, capsys):
    frames = [np.maximum(f, np.roll(f, 90, axis=1)) for f in render_frames(spin_truth(n=3), PLAIN, M_PER_PX)]
    clip = write_clip(tmp_path / "W01_spin.tif", iter(frames), 1000.0)
    code, err, out = _run(tmp_path, capsys, clip)
    assert code == 1 and _nothing_written(out)
    assert "W01_spin.tif: frame 0: 2 balls found" in err


def test_a_ball_that_never_leaves_the_bats_shadow(tmp_path, capsys):
    truth = spin_truth(n=3)
    frames = []
    for f in render_frames(truth, PLAIN, M_PER_PX):
        f = f.copy()
        f[40:120, 60:130] = 20  # a dark barrel over the ball in every frame
        frames.append(f)
    code, err, out = _run(tmp_path, capsys, write_clip(tmp_path / "W01_spin.tif", iter(frames), 1000.0))
    assert code == 1 and _nothing_written(out)
    assert "W01_spin.tif: frame 0:" in err and "found in none of its 3 frames" in err  # no frame numbers: from 0


@pytest.mark.parametrize("missing", [2])
def test_a_dropped_frame(tmp_path, capsys, missing):
    """An MP4 whose packets skip a frame (PyAV writes it so): the timestamps name the frame after the gap."""
    path = tmp_path / "W01_spin.mp4"
    with av.open(str(path), "w") as out:
        s = out.add_stream("libx264", rate=fractions.Fraction(1000))
        s.width, s.height, s.pix_fmt = 240, 160, "yuv420p"
        s.time_base = fractions.Fraction(1, 1000)
        for k, f in enumerate(render_frames(spin_truth(n=5), PLAIN, M_PER_PX)):
            if k == missing:
                continue
            frame = av.VideoFrame.from_ndarray(f, format="gray")
            frame.pts, frame.time_base = k, fractions.Fraction(1, 1000)
            out.mux(s.encode(frame))
        out.mux(s.encode())
    code, err, out = _run(tmp_path, capsys, path)
    assert code == 1 and _nothing_written(out)
    assert (
        f"W01_spin.mp4: frame {missing}: timestamp 0.003 s is" in err and "(a frame dropped or the clock jumped)" in err
    )


def test_a_clip_not_named_for_its_impact_and_camera(tmp_path, capsys):
    code, err, out = _run(tmp_path, capsys, _good(tmp_path, "W01-side.tif"))
    assert code == 1 and _nothing_written(out)
    assert "W01-side.tif: not named {impact_id}_{camera}.{ext}" in err


@pytest.mark.parametrize("target", ["the clip", "a folder", "a device", "a lab's own file", "stdout"])
def test_track_video_writes_through_the_writer(tmp_path, capsys, target):
    """track-video's two tables go through ballbat.writer: it never replaces its clip, a folder, a device or a file
    it did not write (exit 2, one line, nothing touched); it replaces its own earlier tables.
    """
    import os
    import stat

    clip = _good(tmp_path)
    out = {
        "the clip": clip,
        "a folder": tmp_path / "folder",
        "a device": tmp_path / "null",
        "a lab's own file": tmp_path / "mine.csv",
        "stdout": Path("-"),
    }[target]
    if target == "a folder":
        out.mkdir()
    elif target == "a device":
        os.mknod(out, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    elif target == "a lab's own file":
        out.write_text("impact_id,camera\nmy,notes\n")
    before = {p: (p.stat().st_mode, p.read_bytes() if p.is_file() else None) for p in tmp_path.iterdir()}
    code = main(["track-video", str(clip), "--ball-radius-px", f"{RADIUS_PX},{RADIUS_PX}", "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    after = {p: (p.stat().st_mode, p.read_bytes() if p.is_file() else None) for p in tmp_path.iterdir()}
    assert after == before  # nothing written, nothing replaced


def test_track_video_replaces_its_own_tables(tmp_path, capsys):
    clip = _good(tmp_path)
    out = tmp_path / "tracks.csv"
    args = ["track-video", str(clip), "--ball-radius-px", f"{RADIUS_PX},{RADIUS_PX}", "-o", str(out)]
    assert main(args) == 0
    first = out.read_bytes()
    assert first.splitlines()[-1].startswith(b"# ballbat table:")  # sealed: the writer knows it for its own
    assert main(args) == 0, capsys.readouterr().err
    assert out.read_bytes() == first and (tmp_path / "tracks.quality.csv").exists()


def test_the_balls_measured_radius_checks_the_scale_typed(tmp_path, capsys):
    """The ball's radius in the clip against the one given (from Table I and m_per_px): 5 % off warns."""
    clip = _good(tmp_path)
    code, err, _ = _run(tmp_path, capsys, clip)
    assert code == 0 and "warning" not in err
    out = tmp_path / "off" / "tracks.csv"
    wrong = 1.05 * RADIUS_PX  # an m_per_px typed 5 % small
    code = main(["track-video", str(clip), "--ball-radius-px", f"{wrong},{wrong}", "-o", str(out), "--parents"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "W01_spin.tif: the ball measures" in captured.err and "m_per_px" in captured.err
    check = yaml.safe_load(captured.out)["clips"][0]["ball_radius_px"]
    assert check["given"] == pytest.approx(wrong) and check["frames"] == 3
    assert check["measured"] == pytest.approx(RADIUS_PX, rel=0.02)  # the clip's own radius, whatever was given
    assert -6.0 < float(check["off"].rstrip(" %")) < -2.0


def test_track_video_takes_the_options(tmp_path, capsys):
    """`ballbat track-video --background median --ball-fit centroid`: the same ball points as track_clip's."""
    clip, _, _ = toss_clip(tmp_path, name="T1_spin.tif")
    out = tmp_path / "tracks.csv"
    argv = ["track-video", clip.info.path, "--ball-radius-px", f"{TOSS_R},{TOSS_R}", "-o", str(out)]
    assert main([*argv, "--background", "median", "--ball-fit", "centroid", "--search-px", "30"]) == 0
    report = yaml.safe_load(capsys.readouterr().out)
    opt = TrackOptions(TOSS_R, background="median", ball_fit="centroid", search_px=30.0)
    expected = sum(p == "ball" for p in track_clip(clip, opt).rows["point"])
    assert report["clips"][0]["points_found"]["ball"] == expected >= 22
    assert out.with_name("tracks.quality.csv").is_file()
