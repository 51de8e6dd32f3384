"""Regenerate tracked_tracks.csv and tracked_impacts.csv, the example raw-track dataset (output is committed).

12 baseball impacts on the paper's wood bat, rendered as the two cameras of Sec. II would
record them (ballbat.tracks.render: Camera 1 at 3000 fps, Camera 2 at 1000 fps and
mirrored, 0.5 px tracking noise; true e_x = 0.464, e_y = 0.45, bat speed 63-88 mph, psi
0-30 deg), pixels rounded to 0.01 as a tracker exports them. One impact has a tilted spin
axis: its dots do not rotate about the ball's centre and the reduction excludes it.

    .venv/bin/python config/examples/make_tracked.py

The committed files came from the renderer of their time (commit 7c246cf). The renderer has
changed since (its tracking-noise and camera defaults, now the config schema's), so this script
no longer gives them byte for byte: run today it writes a dataset of the same design (the
first seed with one tilted axis is 8, 2754 rows against the committed 2743). The example is an
input the tests pin, so it is kept as committed, not regenerated.
"""

import csv
from pathlib import Path

import numpy as np

from ballbat.pipeline.config import checked_block
from ballbat.properties import load_balls, load_bats
from ballbat.stages import simulate
from ballbat.synthetic import SyntheticSettings
from ballbat.tracks.data import to_long
from ballbat.tracks.render import render_tracks, settings_from_config

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
RENDER = {
    "cameras": {
        "swing": {"fps": 3000, "m_per_px": 0.00074, "mirror": False, "tee_px": [540, 480]},
        "spin": {"fps": 1000, "m_per_px": 0.00125, "mirror": True, "tee_px": [900, 480], "pre_impact_frames": 5},
    },
    "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
    "tilted_fraction": 0.1,
}

balls = load_balls(ROOT / "config" / "balls.csv")
settings = SyntheticSettings(
    impacts={"baseball": {"wood": 12}},
    e_x={"baseball": {"wood": 0.464}},
    e_y={"baseball": 0.45},
    seed=20240612,
    v_bat_mph=(63.0, 88.0),  # the schema's defaults (SyntheticSettings takes every field)
    psi_deg={},
    e_x_scatter=0.0,
    noise={"v_bat_mph": 0.5, "v_ball_mph": 0.5, "theta_deg": 0.5, "omega_rpm": 75.0},
)
ds = simulate.run(settings, balls, load_bats(ROOT / "config" / "bats.csv"))
truth = {k: ds[f"truth_{k}"].values for k in ("v_bat", "v_ball", "theta", "omega", "psi")}
r = np.array([balls[b].r for b in ds["ball"].values])
ids = np.array([f"W{i + 1:02d}" for i in range(ds.sizes["impact"])])
for seed in range(100):  # the first rendering seed with exactly one tilted spin axis
    tracks = render_tracks(
        truth,
        r,
        settings_from_config(checked_block({**RENDER, "seed": seed}, "render")),
        ids,
        ds["ball"].values,
        ds["bat"].values,
    )
    if int((tracks.truth["truth_spin_axis_tilt"] > 0).sum()) == 1:
        break
rows = to_long(tracks)
with open(HERE / "tracked_tracks.csv", "w", newline="") as fh:
    w = csv.writer(fh, lineterminator="\n")
    w.writerow(["impact_id", "camera", "point", "frame", "x_px", "y_px"])
    for i, c, p, f, x, y in zip(
        *(rows[k] for k in ("impact_id", "camera", "point", "frame", "x_px", "y_px")), strict=True
    ):
        w.writerow([i, c, p, int(f), f"{x:.2f}", f"{y:.2f}"])
with open(HERE / "tracked_impacts.csv", "w", newline="") as fh:
    w = csv.writer(fh, lineterminator="\n")
    w.writerow(["impact_id", "bat", "ball"])
    for i, b, a in zip(tracks.impact_id, tracks.bat, tracks.ball, strict=True):
        w.writerow([i, b, a])
tilted = ids[tracks.truth["truth_spin_axis_tilt"] > 0]
print(f"seed {seed}: {tracks.n} impacts, {rows['frame'].size} rows; tilted spin axis: {tilted}")
