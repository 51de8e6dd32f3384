"""Speed of the raw-track chain: render and reduce 10^4 impacts (targets: each under 10 s).

    .venv/bin/python bench/bench_tracks.py [n_impacts]

Prints the frames and points per impact, and the wall time of rendering, of reducing, and of
the long <-> dense conversion a lab's file goes through.
"""

import sys
import time

import numpy as np
from impacts import RENDER_CFG, random_impacts  # bench/impacts.py

from ballbat.pipeline.config import checked_block
from ballbat.tracks.data import POINTS, to_dense, to_long
from ballbat.tracks.reduce import reduce_tracks
from ballbat.tracks.render import render_tracks, settings_from_config

N = int(sys.argv[1]) if len(sys.argv) > 1 else 10_000

truth = random_impacts(N, seed=0)
r = np.full(N, 0.0366)
ids = np.arange(N).astype(str)
s = settings_from_config(checked_block(RENDER_CFG, "render"))  # the schema's defaults filled

t0 = time.perf_counter()
tracks = render_tracks(truth, r, s, ids, np.full(N, "baseball"), np.full(N, "wood"))
t1 = time.perf_counter()
red = reduce_tracks(tracks, {"swing": s.swing.camera, "spin": s.spin.camera}, s.rig)
t2 = time.perf_counter()
rows = to_long(tracks)
t3 = time.perf_counter()
index = rows["impact_id"].astype(np.int64)
to_dense(index, rows["camera"], rows["point"], rows["frame"], rows["x_px"], rows["y_px"], N)
t4 = time.perf_counter()

frames = {c: np.isfinite(tracks.cameras[c].x["ball"]).sum(axis=1).mean() for c in POINTS}
points = rows["frame"].size / N
print(f"impacts: {N}; tracked frames per impact (ball): swing {frames['swing']:.0f}, spin {frames['spin']:.0f}")
print(f"tracked points per impact (all cameras and points): {points:.0f}; excluded: {int((red.flag != 0).sum())}")
print(f"render: {t1 - t0:.2f} s   (target < 10 s)")
print(f"reduce: {t2 - t1:.2f} s   (target < 10 s)")
print(f"dense -> long rows: {t3 - t2:.2f} s; long rows -> dense: {t4 - t3:.2f} s")
