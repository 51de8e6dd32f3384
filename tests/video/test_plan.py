"""One job per batch of clips (ballbat.video.plan, ballbat.stages.clip_tracks; docs/video.md, "In the workflow").

The plan: every clip in exactly one batch, in the import's order, the batches fixed by the clips'
names. The batch file: what tracking gave, written and read back unchanged. The workflow's view:
each batch's inputs, params and resources (tests/workflow/test_video.py runs them).
"""

from __future__ import annotations

import copy
from argparse import Namespace

import numpy as np
import pytest
from video_clips import quality_clip

from ballbat.stages.clip_tracks import GatheredClips, batch_clips, batch_dataset
from ballbat.tracks.data import POINTS
from ballbat.tracks.formats import FileTracks, FormatError
from ballbat.video.plan import (
    TRACK_BASE_MB,
    batch_mem_mb,
    batch_runtime_min,
    folder_clips,
    plan_batches,
    rendered_clips,
)
from ballbat.workflow_inputs import WorkflowInputs
from workflow_helpers import ROOT


def _clips(n: int) -> list[tuple[str, str, str]]:
    return [(f"W{i:02d}", c, f"lab/W{i:02d}_{c}.cine") for i in range(n) for c in ("swing", "spin")]


@pytest.mark.parametrize(("n", "per_job"), [(0, 3), (1, 3), (7, 3), (9, 3), (20, 1), (20, 8), (5, 100)])
def test_every_clip_is_in_exactly_one_batch_in_the_imports_order(n, per_job):
    clips = _clips(n)
    batches = plan_batches(reversed(clips), per_job)  # the order given does not matter
    flat = [c for b in batches for c in b]
    assert flat == sorted(clips, key=lambda c: (c[0], c[1]))  # each once, in the import's order
    assert len(batches) == -(-len(clips) // per_job)
    assert all(len(b) == per_job for b in batches[:-1]) and all(1 <= len(b) <= per_job for b in batches)


def test_the_batches_depend_on_the_names_only_so_a_changed_clip_reruns_its_batch_alone(tmp_path):
    """Planned from a folder twice, the content of one clip changed between: the same batches; only the
    changed clip's batch has another sha256 among its params (the other batches' params are the same).
    """
    lab = tmp_path / "lab"
    lab.mkdir()
    for i in range(5):
        for c in ("swing", "spin"):
            (lab / f"W{i}_{c}.tif").write_bytes(b"clip %d %s" % (i, c.encode()))
    (lab / "impacts.csv").write_text("impact_id,bat,ball\n")
    (lab / "notes.txt").write_text("not a clip")

    def params(per_job: int) -> list[dict]:
        cfg = copy.deepcopy(_config())
        cfg["datasets"]["vid"] = _video_dataset(lab, per_job)
        inputs = WorkflowInputs(cfg, ROOT)
        n = len(inputs.clip_batches("vid"))
        return [inputs.batch_hashes(Namespace(dataset="vid", batch=str(k))) for k in range(n)]

    before = params(3)
    assert len(before) == 4  # 10 clips in batches of 3
    (lab / "W2_spin.tif").write_bytes(b"clip 2 spin, filmed again")
    after = params(3)
    changed = [k for k in range(4) if before[k] != after[k]]
    assert changed == [1]  # W1_swing, W2_spin, W2_swing: the second batch alone
    cfg = copy.deepcopy(_config())
    cfg["datasets"]["vid"] = _video_dataset(lab, 3)
    inputs, wc = WorkflowInputs(cfg, ROOT), Namespace(dataset="vid", batch="1")
    # a lab's frames are not known before the job: a 4K frame of 4 bytes a pixel, 16 times over 500 MB
    assert inputs.clip_batch_mem_mb(wc) == 500 + 531
    assert inputs.get_batch_clips(wc)["clips"] == [
        str(lab / n) for n in ("W1_swing.tif", "W2_spin.tif", "W2_swing.tif")
    ]
    assert after[1]["W2_spin.tif"] != before[1]["W2_spin.tif"]


def test_a_folder_is_planned_as_the_import_lists_it(tmp_path):
    for name in ("b_swing.mkv", "a_spin.mkv", "a_swing.mkv", "b_spin.mkv", "impacts.csv", "readme.txt"):
        (tmp_path / name).write_bytes(b"")
    clips = folder_clips({"dir": str(tmp_path), "pattern": "{impact_id}_{camera}.{ext}"})
    assert [c[2] for c in clips] == [
        str(tmp_path / n) for n in ("a_spin.mkv", "a_swing.mkv", "b_spin.mkv", "b_swing.mkv")
    ]


def test_a_filmed_experiments_clips_are_named_as_render_clips_names_them():
    from ballbat.stages.clips import render_clips  # noqa: F401  (the writer: clip_name, from the same plan)

    clips = rendered_clips("results/video/clips", 12, "mkv")
    assert len(clips) == 24 and clips[0] == ("0", "spin", "results/video/clips/0_spin.mkv")
    assert [c[0] for c in clips[:6]] == ["0", "0", "1", "1", "10", "10"]  # the import's (text) order
    with pytest.raises(ValueError, match="avi"):
        rendered_clips("x", 1, "avi")


@pytest.mark.parametrize("bad", [0, -1, 2.5, True, "8"])
def test_a_batch_size_that_is_not_a_whole_number_of_clips_is_refused(bad):
    with pytest.raises(ValueError, match="clips_per_job"):
        plan_batches(_clips(2), bad)


def test_two_clips_of_one_impact_and_camera_are_refused():
    with pytest.raises(ValueError, match=r"W00_swing\.mp4"):
        plan_batches([*_clips(1), ("W00", "swing", "lab/W00_swing.mp4")], 2)


def test_each_batch_job_declares_one_thread_and_its_memory_and_time():
    """Memory from the frame (16 copies over the base), not from a clip's length; time from the frames."""
    assert batch_mem_mb(0) == TRACK_BASE_MB
    assert batch_mem_mb(1024 * 512) == TRACK_BASE_MB + 9  # 16 x 0.52 MB
    assert batch_runtime_min(0) == 5 and batch_runtime_min(1200) == 6 and batch_runtime_min(12001) == 16
    cfg = _config()
    example = _example()
    cfg["datasets"]["video"] = example
    inputs = WorkflowInputs(cfg, ROOT)
    wc = Namespace(dataset="video", batch="0")
    per_job = example["render"]["video"]["clips_per_job"]  # the schema's default (8)
    assert len(inputs.clip_batches("video")) == 40 // per_job  # 20 impacts, 2 cameras
    assert inputs.clip_batch_mem_mb(wc) == TRACK_BASE_MB + 9  # 1024 x 512 8-bit
    # 8 clips: 4 swing (120 frames at most) and 4 spin (60)
    assert inputs.clip_batch_runtime(wc) == batch_runtime_min(4 * 120 + 4 * 60)
    assert inputs.get_batch_clips(wc) == {"clips": "results/video/clips"}
    files = inputs.get_clip_batch_files(Namespace(dataset="video"))
    assert files == [f"results/video/clip_tracks/batch_{k}.nc" for k in range(5)]
    with pytest.raises(ValueError, match="no batch 5"):
        inputs.get_tracker_settings(Namespace(dataset="video", batch="5"))


def test_a_batchs_params_are_what_its_tracker_reads():
    """The clips, each camera's scale, the markers, the impacts table: not the rig or the mirrors."""
    cfg = _config()
    cfg["datasets"]["video"] = _example()
    wc = Namespace(dataset="video", batch="1")
    got = WorkflowInputs(cfg, ROOT).get_tracker_settings(wc)
    assert got["clips"][0] == ["12", "spin", "results/video/clips/12_spin.mkv"] and len(got["clips"]) == 8
    assert got["m_per_px"] == {"swing": 0.00074, "spin": 0.00125}
    assert got["video"] == {"dot_radius_mm": 4.0, "marker_radius_mm": 6.0}
    assert got["impacts"] == "results/video/clips/impacts.csv"
    cfg["datasets"]["video"]["render"]["rig"]["pivot_to_tip_in"] = 33.0
    cfg["datasets"]["video"]["render"]["cameras"]["spin"]["mirror"] = True
    assert WorkflowInputs(cfg, ROOT).get_tracker_settings(wc) == got


def _tracked(iid: str, cam: str, seed: int) -> tuple[FileTracks, dict]:
    """A clip's tracks and quality table as tracking gives them (the points found are the tracks)."""
    q = quality_clip(iid, cam, 15, seed)
    found = q["left_out"] == ""
    tracks = {p: (q["frame"][found & (q["point"] == p)], q["x_px"][found & (q["point"] == p)],
                  q["y_px"][found & (q["point"] == p)]) for p in POINTS[cam]}  # fmt: skip
    fps, exposure = (None, None) if cam == "spin" else (3000.0, 50e-6)
    source = {"fps": "the clip" if fps else "", "exposure_s": "the clip" if exposure else ""}
    return FileTracks(f"lab/{iid}_{cam}.tif", tracks, fps=fps, source=source, exposure_s=exposure), q


def test_a_batch_file_gives_back_what_tracking_gave(tmp_path):
    """Written (with units and provenance) and read back: each clip's tracks and quality table, value for value."""
    from ballbat.pipeline.ncio import read_dataset, write_dataset

    clips = [("W1", "spin", "lab/W1_spin.tif"), ("W1", "swing", "lab/W1_swing.tif"), ("W2", "spin", "lab/W2_spin.tif")]
    made = [_tracked(i, c, seed) for seed, (i, c, _) in enumerate(clips)]
    ds = batch_dataset(clips, [m[0] for m in made], [m[1] for m in made])
    assert ds["clip_fps"].attrs["units"] == "Hz" and ds.attrs["n_clips"] == 3
    path = write_dataset(ds, tmp_path / "batch_0.nc", title="t", rule="track_clips", inputs={}, config={})
    back = batch_clips(read_dataset(path))
    assert list(back) == [c[2] for c in clips]
    for (ft, q), (ft0, q0) in zip(back.values(), made, strict=True):
        assert ft.path == ft0.path and ft.fps == ft0.fps and ft.source == ft0.source and ft.exposure_s == ft0.exposure_s
        for p in POINTS[ft.path.split("_")[1].removesuffix(".tif")]:
            for a, b in zip(ft.tracks[p], ft0.tracks[p], strict=True):
                assert a.dtype == b.dtype and np.array_equal(a, b)
        for k in q0:
            assert np.array_equal(q[k].astype(q0[k].dtype), q0[k], equal_nan=q0[k].dtype.kind == "f"), k


def test_the_gathered_reader_reads_each_clip_once_and_names_one_no_batch_tracked(tmp_path):
    from pathlib import Path

    clips = [("W1", "spin", "lab/W1_spin.tif"), ("W1", "swing", "lab/W1_swing.tif")]
    made = [_tracked(i, c, seed) for seed, (i, c, _) in enumerate(clips)]
    gathered = GatheredClips([batch_dataset(clips, [m[0] for m in made], [m[1] for m in made])])
    read = gathered({"video": {}}, {"W1": 0.036, "W3": 0.036})
    got = read([(Path("lab/W1_swing.tif"), "W1", "swing", {}), (Path("lab/W3_swing.tif"), "W3", "swing", {})])
    assert got[0].path == "lab/W1_swing.tif" and isinstance(got[1], FormatError)
    assert "lab/W3_swing.tif: no batch of this run tracked it" in got[1].problems[0]
    assert gathered.unread() == ["lab/W1_spin.tif"]  # tracked, not found by the import: named
    assert np.array_equal(gathered.quality()["frame"], made[1][1]["frame"])


# -- configs -------------------------------------------------------------------------------


def _config() -> dict:
    from ballbat.config_checks import load_config

    return load_config(ROOT / "config" / "config.yaml")


def _example() -> dict:
    """The filmed example's dataset (config/examples/video.yaml) with the schema's defaults."""
    import yaml

    from ballbat.config_checks import validate_config

    cfg = _config()
    ex = yaml.safe_load((ROOT / "config" / "examples" / "video.yaml").read_text())["datasets"]["video"]
    cfg["datasets"]["video"] = ex
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    validate_config(cfg, schema)
    return cfg["datasets"]["video"]


def _video_dataset(folder, per_job: int) -> dict:
    cams = {c: {"m_per_px": 0.001, "mirror": False} for c in ("swing", "spin")}
    return {
        "tracks": {
            "dir": str(folder),
            "format": "video",
            "pattern": "{impact_id}_{camera}.{ext}",
            "impacts": str(folder / "impacts.csv"),
            "cameras": cams,
            "video": {"dot_radius_mm": 4.0, "marker_radius_mm": 6.0, "clips_per_job": per_job},
        }
    }


def _tracker(clips: list, **m_per_px) -> dict:
    return {
        "clips": clips,
        "m_per_px": {"swing": 0.001, "spin": 0.001, **m_per_px},
        "video": {"dot_radius_mm": 4.0, "marker_radius_mm": 6.0},
        "impacts": "",
        "where": "config datasets.vid.tracks",
    }


def test_a_batch_with_a_truncated_clip_fails_naming_the_file_and_the_frame(tmp_path):
    """A Photron clip cut after 2 of its 15 frames (tests/data/video): the batch stops on frame 2, naming it."""
    import shutil

    from ballbat.properties import load_balls
    from ballbat.stages import clip_tracks

    data = ROOT / "tests" / "data" / "video"
    for ext in (".cihx", ".mraw"):
        shutil.copy(data / f"ball_12bit_2frames{ext}", tmp_path / f"W1_spin{ext}")
    (tmp_path / "impacts.csv").write_text("impact_id,bat,ball\nW1,wood,baseball\n")
    tracker = _tracker([["W1", "spin", str(tmp_path / "W1_spin.cihx")]])
    tracker["impacts"] = str(tmp_path / "impacts.csv")
    with pytest.raises(FormatError, match=r"W1_spin\.mraw: frame 2: the file ends .*truncated"):
        clip_tracks.run(tracker, load_balls(ROOT / "config" / "balls.csv"))


def test_a_batch_without_a_cameras_scale_names_the_config_key():
    from ballbat.properties import InputError
    from ballbat.stages import clip_tracks

    with pytest.raises(InputError, match=r"datasets\.vid\.tracks\.cameras\.spin\.m_per_px: missing"):
        clip_tracks.run(_tracker([["W1", "spin", "W1_spin.tif"]], spin=None), {})
