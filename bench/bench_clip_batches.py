"""Memory and CPU of one track_clips job as its batch grows (docs/video.md, "In the workflow").

    .venv/bin/python bench/bench_clip_batches.py [RESULTS_DATASET] > bench_clip_batches.out

Reads the clips a run of ``config/examples/video.yaml`` drew (default ``results/video``: its
``clips/`` folder, 40 FFV1 clips of 1024 x 512, 8 bit) and tracks batches of 1, 8 and 40 of
them, each in a fresh process as the rule's job is (``ballbat.stages.clip_tracks.run``, then the
batch file written as the rule writes it), reporting each job's peak resident memory
(``ru_maxrss``) and its CPU time. The tracker streams its frames, so a job's memory should not
grow with its clips; ``ballbat.video.plan.batch_mem_mb`` is what each job declares. Last, the
batches of 8 are gathered (``GatheredClips``) and compared with the batch of 40, clip by clip.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from ballbat.pipeline.ncio import read_dataset
from ballbat.stages.clip_tracks import batch_clips
from ballbat.video.plan import batch_mem_mb, folder_clips, plan_batches

ROOT = Path(__file__).resolve().parents[1]
DATASET = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "results" / "video"
JOB = """
import json, sys
from ballbat.pipeline.ncio import write_dataset
from ballbat.properties import load_balls
from ballbat.stages import clip_tracks
tracker, out = json.loads(sys.argv[1]), sys.argv[2]
batch = clip_tracks.run(tracker, load_balls(sys.argv[3]))
write_dataset(batch, out, title="bench", rule="track_clips", inputs={}, config={})
"""


def job(clips: list, out: Path) -> tuple[float, float]:
    """Track ``clips`` in a fresh process; return its peak RSS (MB) and CPU time (s)."""
    tracker = {
        "clips": [list(c) for c in clips],
        "m_per_px": {"swing": 0.00074, "spin": 0.00125},  # config/examples/video.yaml
        "video": {"dot_radius_mm": 4.0, "marker_radius_mm": 6.0},
        "impacts": str(DATASET / "clips" / "impacts.csv"),
        "where": "config datasets.video.render",
    }
    args = [sys.executable, "-c", JOB, json.dumps(tracker), str(out), str(ROOT / "config" / "balls.csv")]
    proc = subprocess.Popen(args)
    _, status, usage = os.wait4(proc.pid, 0)  # this job's own resource use
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode:
        raise SystemExit(f"the job failed ({proc.returncode})")
    return usage.ru_maxrss / 1024, usage.ru_utime + usage.ru_stime  # ru_maxrss: kB on Linux


def main() -> None:
    """Track batches of 1, 8 and 40 clips, each in its own process; compare the 8s gathered with the 40."""
    clips = folder_clips({"dir": str(DATASET / "clips"), "pattern": "{impact_id}_{camera}.{ext}"})
    where = (DATASET / "clips").resolve()
    where = where.relative_to(ROOT) if where.is_relative_to(ROOT) else where
    print(f"{len(clips)} clips in {where}; each job declares {batch_mem_mb(1024 * 512)} MB")
    with tempfile.TemporaryDirectory() as tmp:
        out = {}
        for per_job in (1, 8, 40):
            batches = plan_batches(clips, per_job)
            for k, batch in enumerate(batches[:2] if per_job == 1 else batches):  # two single clips
                path = Path(tmp) / f"b{per_job}_{k}.nc"
                rss, cpu = job(batch, path)
                rows = read_dataset(path).sizes["row"]
                print(f"batch {k} of {len(batch):2d} clips: peak RSS {rss:6.1f} MB, CPU {cpu:5.1f} s ({rows} points)")
                out.setdefault(per_job, []).append(path)
        eights = {}
        for p in out[8]:
            eights.update(batch_clips(read_dataset(p)))
        whole = batch_clips(read_dataset(out[40][0]))
        same = list(eights) == list(whole) and all(
            all(
                np.array_equal(a, b, equal_nan=True)
                for p in whole[c][0].tracks
                for a, b in zip(whole[c][0].tracks[p], eights[c][0].tracks[p], strict=True)
            )
            for c in whole
        )
        print(f"five batches of 8 against one of 40: the same tracks of every clip: {same}")


if __name__ == "__main__":
    main()
