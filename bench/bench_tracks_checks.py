"""False alarms of the raw-track cross-checks (issue 18) on clean synthetic data.

    .venv/bin/python bench/bench_tracks_checks.py [n_seeds]

Renders the default config's ``synthetic`` dataset (108 impacts, 2 px tracking noise, 3 % of
tilted spin axes) with ``n_seeds`` seeds (default 50; the simulation and the rendering
seeds both vary), reduces and cross-checks each as the reduce rule does
(:func:`ballbat.tracks.checks.cross_check`), and counts what the checks added: datasets
stopped, impacts excluded by a new reason (cameras disagree, implausible), glitches removed,
and warnings. Also prints the pooled observables' spread over the seeds (g, speed ratio, tip
arc, dot radius). Clean data should raise none.
"""

import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

from ballbat.pipeline.config import load_config
from ballbat.properties import InputError, load_balls, load_bats
from ballbat.synthetic import SyntheticSettings, simulate_experiment
from ballbat.tracks.checks import cross_check
from ballbat.tracks.data import camera_block
from ballbat.tracks.io import cameras_from_config
from ballbat.tracks.reduce import ReduceFlag, reduce_tracks
from ballbat.tracks.render import render_tracks, settings_from_config
from ballbat.tracks.stage import SIMULATED_TRUTH

ROOT = Path(__file__).resolve().parents[1]
N = int(sys.argv[1]) if len(sys.argv) > 1 else 50
cfg = load_config(ROOT / "config" / "config.yaml")["datasets"]["synthetic"]
balls, bats = load_balls(ROOT / "config" / "balls.csv"), load_bats(ROOT / "config" / "bats.csv")
cameras, rig = cameras_from_config(camera_block(cfg["render"]), "render")

new = (ReduceFlag.CAMERAS_DISAGREE, ReduceFlag.IMPLAUSIBLE)
stopped, flags, glitches, warnings, impacts = [], Counter(), 0, 0, 0
observed = {k: [] for k in ("g_swing", "g_spin", "speed", "arc")}
t0 = time.perf_counter()
for seed in range(N):
    sim = simulate_experiment(SyntheticSettings(**{**cfg["synthetic"], "seed": 1000 + seed}), balls, bats)
    truth = {k: sim[f"truth_{k}"].values for k in SIMULATED_TRUTH if f"truth_{k}" in sim}
    r = np.array([balls[b].r for b in sim["ball"].values.astype(str)])
    s = settings_from_config({**cfg["render"], "seed": 2000 + seed})
    tr = render_tracks(truth, r, s, sim["impact"].values.astype(str), sim["ball"].values, sim["bat"].values)
    red = reduce_tracks(tr, cameras, rig)
    impacts += tr.n
    glitches += int(sum(v.sum() for v in red.n_outliers.values()))
    try:
        verdict = cross_check(red, balls, bats, f"seed {seed}")
    except InputError as exc:
        stopped.append((seed, exc.problems))
        continue
    warnings += len(verdict.warnings)
    flags.update(ReduceFlag(int(f)).name for f in red.flag if f in new)
    for k, (val, _) in verdict.observed.items():
        observed[k].append(val)
print(f"{N} datasets, {impacts} impacts, {time.perf_counter() - t0:.0f} s")
print(f"datasets stopped: {len(stopped)}")
for seed, problems in stopped:
    print(f"  seed {seed}: " + "\n    ".join(problems))
print(f"impacts excluded by a new check: {sum(flags.values())} {dict(flags)}")
print(f"single-frame glitches removed: {glitches}")
print(f"warnings: {warnings}")
for k, v in observed.items():
    v = np.asarray(v)
    if v.size:
        print(f"{k}: mean {v.mean():.4f}, sd {v.std(ddof=1):.4f}, range [{v.min():.4f}, {v.max():.4f}]")
