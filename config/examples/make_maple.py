"""Regenerate maple_impacts.csv, the example measured dataset (run once; output is committed).

31 baseball impacts on a maple bat that is not in the paper (maple_bats.csv): 30 drawn with
ballbat's forward model (Sec. III, true e_x = 0.42, e_y = 0.45, bat speed 63-88 mph, psi
0-30 deg) plus the default measurement noise, rounded as a lab would record them, and one
impact whose spin was mis-read (18500 rpm for 1850): its psi cannot be reconstructed, so
the workflow excludes it and says why.

    .venv/bin/python config/examples/make_maple.py
"""

import csv
import sys
from pathlib import Path

from ballbat.properties import load_balls, load_bats
from ballbat.stages.simulate import run as simulate
from ballbat.synthetic import SyntheticSettings
from ballbat.units import DEGREE, MPH, RPM

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
#: Where the table goes (the committed example; give another path as the first argument to compare).
OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "maple_impacts.csv"

settings = SyntheticSettings(
    impacts={"baseball": {"maple": 30}},
    e_x={"baseball": {"maple": 0.42}},
    e_y={"baseball": 0.45},
    seed=20240611,
    v_bat_mph=(63.0, 88.0),
    psi_deg={"baseball": (0.0, 30.0)},
    noise={"v_bat_mph": 0.5, "v_ball_mph": 0.5, "theta_deg": 0.5, "omega_rpm": 75.0},
    e_x_scatter=0.0,
)
ds = simulate(settings, load_balls(ROOT / "config" / "balls.csv"), load_bats(HERE / "maple_bats.csv"))
columns = [
    ("v_bat_mph", "v_bat", MPH, 1),
    ("v_ball_mph", "v_ball", MPH, 1),
    ("theta_deg", "theta", DEGREE, 1),
    ("omega_rpm", "omega", RPM, 0),
]
rows = []
for i in range(ds.sizes["impact"]):
    row = {"impact_id": f"MP{i + 1:02d}", "bat": "maple", "ball": "baseball"}
    for col, var, unit, digits in columns:
        row[col] = f"{float(ds[var].values[i]) / unit:.{digits}f}"
        row[f"{col}_err"] = f"{float(ds[var + '_err'].values[i]) / unit:g}"
    rows.append(row)
glitch = dict(rows[-1], impact_id="MP31", v_bat_mph="71.2", v_ball_mph="60.4", theta_deg="7.9", omega_rpm="18500")
rows.append(glitch)
header = ["impact_id", "bat", "ball"] + [c for c, *_ in columns] + [f"{c}_err" for c, *_ in columns]
with open(OUT, "w", newline="") as fh:
    w = csv.DictWriter(fh, header, lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
