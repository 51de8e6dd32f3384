"""Regenerate hickory_impacts.csv, the example of a bat measured in a lab's terms (run once; output is committed).

The bat sheet hickory_bats.csv is in the lab convention of ASTM F2398 / F2219 (length 34 in,
weight 32 oz, balance point 23.0 in from the knob, MOI 11200 oz in^2 about the pivot 6 in
from the knob, impact 6 in from the barrel tip, barrel diameter 2.6 in, Iz 11.0 oz in^2);
ballbat converts it to the paper's convention (M 32 oz, I0 = 11200 - 32 * 17^2 = 1952 oz in^2,
b = 34 - 6 - 23 = 5 in, R = 1.3 in). 30 baseball impacts are drawn with ballbat's forward
model on that bat (Sec. III; true e_x = 0.455, e_y = 0.45) plus the default measurement
noise and rounded as a lab would record them.

    .venv/bin/python config/examples/make_hickory.py
"""

import csv
from pathlib import Path

from ballbat.properties import load_balls, load_bats
from ballbat.stages.simulate import run as simulate
from ballbat.synthetic import SyntheticSettings
from ballbat.units import DEGREE, MPH, RPM

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
#: The truth the impacts are drawn with.
E_X_TRUE = 0.455

settings = SyntheticSettings(
    impacts={"baseball": {"hickory": 30}},
    e_x={"baseball": {"hickory": E_X_TRUE}},
    e_y={"baseball": 0.45},
    seed=20261126,
    v_bat_mph=(63.0, 88.0),
    psi_deg={"baseball": (0.0, 30.0)},
    noise={"v_bat_mph": 0.5, "v_ball_mph": 0.5, "theta_deg": 0.5, "omega_rpm": 75.0},
    e_x_scatter=0.0,
)
ds = simulate(settings, load_balls(ROOT / "config" / "balls.csv"), load_bats(HERE / "hickory_bats.csv"))
columns = [
    ("v_bat_mph", "v_bat", MPH, 1),
    ("v_ball_mph", "v_ball", MPH, 1),
    ("theta_deg", "theta", DEGREE, 1),
    ("omega_rpm", "omega", RPM, 0),
]
rows = []
for i in range(ds.sizes["impact"]):
    row = {"impact_id": f"HK{i + 1:02d}", "bat": "hickory", "ball": "baseball"}
    for col, var, unit, digits in columns:
        row[col] = f"{float(ds[var].values[i]) / unit:.{digits}f}"
        row[f"{col}_err"] = f"{float(ds[var + '_err'].values[i]) / unit:g}"
    rows.append(row)
header = ["impact_id", "bat", "ball"] + [c for c, *_ in columns] + [f"{c}_err" for c, *_ in columns]
with open(HERE / "hickory_impacts.csv", "w", newline="") as fh:
    w = csv.DictWriter(fh, header, lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
