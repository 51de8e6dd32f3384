"""False alarms and power of the raw-track cross-checks (issue 18) on synthetic data.

    .venv/bin/python bench/bench_tracks_checks.py [n_seeds] [--mistakes]

Renders the default config's ``synthetic`` dataset (108 impacts, 2 px tracking noise, 3 % of
tilted spin axes) with ``n_seeds`` seeds (default 50; the simulation and the rendering
seeds both vary), reduces and cross-checks each as the reduce rule does
(:func:`ballbat.tracks.verdict.cross_check`), and counts what the checks added: datasets
stopped, impacts excluded by a new reason (cameras disagree, implausible), glitches removed,
and warnings. Also prints the pooled observables' spread over the seeds (g, speed ratio, tip
arc, dot radius). Clean data should raise none.

With ``--mistakes``, each seed's tracks are also reduced with each of the review's mistakes
(issue 18) and the bench counts how often the dataset stops, and how often the message names
the mistake as the likeliest.
"""

import sys
import time
from collections import Counter
from dataclasses import replace
from pathlib import Path

import numpy as np

from ballbat.config_checks import load_config
from ballbat.properties import InputError, load_balls, load_bats
from ballbat.stages import simulate
from ballbat.stages.impacts import SIMULATED_TRUTH
from ballbat.synthetic import SyntheticSettings
from ballbat.tracks.data import CameraTracks, Rig, camera_block
from ballbat.tracks.io import cameras_from_config
from ballbat.tracks.reduce import ReduceFlag, reduce_tracks
from ballbat.tracks.render import render_tracks, settings_from_config
from ballbat.tracks.verdict import cross_check

ROOT = Path(__file__).resolve().parents[1]
ARGS = [a for a in sys.argv[1:] if not a.startswith("--")]
N = int(ARGS[0]) if ARGS else 50
MISTAKES = "--mistakes" in sys.argv
cfg = load_config(ROOT / "config" / "config.yaml")["datasets"]["synthetic"]
balls, bats = load_balls(ROOT / "config" / "balls.csv"), load_bats(ROOT / "config" / "bats.csv")
cameras, rig = cameras_from_config(camera_block(cfg["render"]), "render")

new = (ReduceFlag.CAMERAS_DISAGREE, ReduceFlag.IMPLAUSIBLE)
power: dict = {}


def _mapped(tr, fn, which=("swing", "spin")):
    out = {}
    for name, ct in tr.cameras.items():
        xs, ys = {}, {}
        for p in ct.x:
            xs[p], ys[p] = fn(name, ct.x[p], ct.y[p]) if name in which else (ct.x[p], ct.y[p])
        out[name] = CameraTracks(ct.frame0, xs, ys)
    return replace(tr, cameras=out)


def mistakes(tr, cameras, rig):
    """The review's mistakes: name -> (cameras, rig, tracks, the words the stop message should name)."""
    out = {}
    sw, sp = cameras["swing"], cameras["spin"]
    out["swing m_per_px in mm/px"] = (
        {**cameras, "swing": replace(sw, m_per_px=sw.m_per_px * 1e3)},
        rig,
        tr,
        "cameras.swing.m_per_px is in mm",
    )
    for c in ("swing", "spin"):
        for f, word in ((2.0, "high"), (0.5, "low")):
            cam = cameras[c]
            out[f"{c} fps x{f:g}"] = (
                {**cameras, c: replace(cam, fps=cam.fps * f)},
                rig,
                tr,
                f"cameras.{c}.fps is 2x too {word}",
            )
    out["rig in metres"] = (
        cameras,
        Rig(rig.pivot_to_tip / 39.37, rig.pivot_to_impact / 39.37, 0.0, 0.0),
        tr,
        "the rig lengths are in metres",
    )
    cm = Rig(rig.pivot_to_tip * 2.54, rig.pivot_to_impact * 2.54, 0.0, 0.0)
    out["rig in cm"] = (cameras, cm, tr, "the rig lengths are in cm")
    out["y up, both cameras"] = (cameras, rig, _mapped(tr, lambda c, x, y: (x, 800.0 - y)), "y points up in both")
    out["y up, swing camera"] = (
        cameras,
        rig,
        _mapped(tr, lambda c, x, y: (x, 800.0 - y), ("swing",)),
        "y points up in the swing",
    )
    mm = {"swing": sw.m_per_px * 1e3, "spin": sp.m_per_px * 1e3}
    out["coordinates in mm"] = (
        cameras,
        rig,
        _mapped(tr, lambda c, x, y: (x * mm[c], y * mm[c])),
        "x_px and y_px are millimetres, not pixels",
    )
    for name in out:
        power.setdefault(name, Counter())
    return out


stopped, flags, glitches, warnings, impacts = [], Counter(), 0, 0, 0
observed = {k: [] for k in ("g_swing", "g_spin", "speed", "arc")}
t0 = time.perf_counter()
for seed in range(N):
    sim = simulate.run(SyntheticSettings(**{**cfg["synthetic"], "seed": 1000 + seed}), balls, bats)
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
    if MISTAKES:
        for name, (cams, rg, tracks, expect) in mistakes(tr, cameras, rig).items():
            red = reduce_tracks(tracks, cams, rg)
            try:
                cross_check(red, balls, bats, "render")
                power[name]["passed"] += 1
            except InputError as exc:
                text = "\n".join(exc.problems)
                power[name]["stopped"] += 1
                power[name]["named"] += f"most likely {expect}" in text
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
for name, c in power.items():
    print(f"{name}: stopped {c['stopped']} of {N}, the mistake named {c['named']}, passed {c['passed']}")
