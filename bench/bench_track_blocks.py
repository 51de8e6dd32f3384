"""Memory of a dataset with one long track: padded to the longest (one block) against blocks of impacts.

    .venv/bin/python bench/bench_track_blocks.py [n_impacts] [factor]

Renders ``n_impacts`` (default 3000) impacts, makes impact 0's swing-camera ball track
``factor`` (default 10) times as long (frames at rest before it), writes the tracks as a NetCDF
tracks file and, in a fresh process each, reads and reduces it (``ballbat.stages.reduce.run``,
cross-checks on, no calibration reruns) twice: with every impact in one block padded to the
longest track (``BLOCK_BYTES`` set beyond any size: the layout before issue 34's blocks), and
with the default block budget. Prints each run's peak of traced allocations (tracemalloc: numpy's
arrays included) during the reduction, the process's peak resident memory (getrusage: reading and
reducing) and the times, with the tracks' own size.
"""

import json
import resource
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
from impacts import RENDER_CFG, random_impacts  # bench/impacts.py

from ballbat.pipeline.config import checked_block
from ballbat.pipeline.ncio import write_dataset
from ballbat.tracks.render import render_tracks, settings_from_config

COLS = ("impact_id", "camera", "point", "frame", "x_px", "y_px")


def write_tracks(path: Path, n: int, factor: int) -> int:
    """Write the tracks file; return the tracked points' own size in bytes (x and y, 8 bytes each)."""
    from ballbat.stages.render import tracks_dataset

    s = settings_from_config(checked_block(RENDER_CFG, "render"))
    tracks = render_tracks(
        random_impacts(n, seed=0),
        np.full(n, 0.0366),
        s,
        np.arange(n).astype(str),
        np.full(n, "baseball"),
        np.full(n, "wood"),
    )
    ds = tracks_dataset(tracks)
    rows = {k: ds[k].values for k in COLS}
    sel = (rows["impact_id"] == "0") & (rows["camera"] == "swing") & (rows["point"] == "ball")
    first = np.argmin(np.where(sel, rows["frame"], np.iinfo(np.int64).max))
    lo, hi = rows["frame"][sel].min(), rows["frame"][sel].max()
    k = (factor - 1) * int(hi - lo + 1)
    noise = 0.5 * np.random.default_rng(0).standard_normal((2, k))
    extra = {
        "impact_id": np.full(k, "0"),
        "camera": np.full(k, "swing"),
        "point": np.full(k, "ball"),
        "frame": lo - 1 - np.arange(k),
        "x_px": rows["x_px"][first] + noise[0],
        "y_px": rows["y_px"][first] + noise[1],
    }
    out = ds.drop_dims("row").assign(
        {c: ("row", np.concatenate([rows[c], extra[c]]).astype(rows[c].dtype), ds[c].attrs) for c in COLS}
    )
    write_dataset(out, path, title="bench tracks", rule="bench", inputs={}, config={})
    return (rows["frame"].size + k) * 16


def run(path: str, mode: str) -> dict:
    """Read and reduce ``path`` in this process (``mode``: one block or the default blocks); return the measures."""
    from ballbat.properties import load_balls, load_bats
    from ballbat.stages import reduce
    from ballbat.tracks import data
    from ballbat.tracks.io import load_tracks

    root = Path(__file__).resolve().parents[1] / "config"
    balls, bats = load_balls(root / "balls.csv"), load_bats(root / "bats.csv")
    block = checked_block(RENDER_CFG, "render")
    settings = reduce.ReduceSettings.from_config(data.camera_block(block), "render", systematics=False)
    if mode == "one":
        data.BLOCK_BYTES = 2**62  # every impact in one block, padded to the longest track
    t0 = time.perf_counter()
    tracks = load_tracks(path, balls=balls, bats=bats)
    t1 = time.perf_counter()
    tracemalloc.start()  # the reduction's allocations only (tracing the reader's many small strings is slow)
    ds = reduce.run(settings, tracks, balls, bats)
    t2 = time.perf_counter()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    padded = sum(a.nbytes for b in tracks.blocks for ct in b.cameras.values() for a in (*ct.x.values(), *ct.y.values()))
    return {
        "blocks": len(tracks.blocks),
        "padded_mb": padded / 1e6,
        "traced_peak_mb": peak / 1e6,
        "maxrss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3,
        "load_s": t1 - t0,
        "reduce_s": t2 - t1,
        "usable": int((ds["ingest_flag"].values == 0).sum()),
        "v_bat_sum": float(np.nansum(ds["v_bat"].values)),
    }


def main() -> None:
    """Write the tracks file, then read and reduce it in a process of its own per layout; print the measures."""
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 3000
    factor = int(sys.argv[2]) if len(sys.argv) > 2 else 10
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "tracks.nc"
        own = write_tracks(path, n, factor)
        print(f"{n} impacts, impact 0's swing ball track {factor}x as long; the tracks' own size {own / 1e6:.1f} MB")
        for mode in ("one", "blocks"):
            out = subprocess.run([sys.executable, __file__, "--run", str(path), mode], capture_output=True, text=True)
            if out.returncode:
                sys.exit(out.stderr)
            m = json.loads(out.stdout.splitlines()[-1])
            what = "padded to the longest (before)" if mode == "one" else "blocks of impacts (after)"
            print(
                f"{what}: {m['blocks']} block(s), padded tracks {m['padded_mb']:.1f} MB; reduction's traced peak "
                f"{m['traced_peak_mb']:.0f} MB, peak resident {m['maxrss_mb']:.0f} MB; load {m['load_s']:.1f} s, "
                f"reduce {m['reduce_s']:.1f} s; {m['usable']} usable, sum of v_bat {m['v_bat_sum']:.9f} m/s"
            )


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--run":
        print(json.dumps(run(sys.argv[2], sys.argv[3])))
    else:
        main()
