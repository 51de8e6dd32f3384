"""What the example scripts make_maple.py and make_hickory.py share.

A bat's impacts drawn with ballbat's forward model and written as a lab records them (mph, deg,
rpm, rounded, with their standard uncertainties).
"""

import csv
from pathlib import Path

from ballbat.properties import load_balls, load_bats
from ballbat.stages.simulate import run as simulate
from ballbat.synthetic import SyntheticSettings
from ballbat.units import DEGREE, MPH, RPM

ROOT = Path(__file__).resolve().parents[2]
#: The lab's columns: (column, variable, unit, decimals recorded).
COLUMNS = [
    ("v_bat_mph", "v_bat", MPH, 1),
    ("v_ball_mph", "v_ball", MPH, 1),
    ("theta_deg", "theta", DEGREE, 1),
    ("omega_rpm", "omega", RPM, 0),
]
HEADER = ["impact_id", "bat", "ball"] + [c for c, *_ in COLUMNS] + [f"{c}_err" for c, *_ in COLUMNS]


def baseball_rows(bat: str, bats_csv: Path, e_x: float, seed: int, prefix: str, n: int = 30) -> list[dict]:
    """``n`` baseball impacts on ``bat`` (true e_x, e_y 0.45, bat speed 63-88 mph, psi 0-30 deg), as a lab's rows."""
    settings = SyntheticSettings(
        impacts={"baseball": {bat: n}},
        e_x={"baseball": {bat: e_x}},
        e_y={"baseball": 0.45},
        seed=seed,
        v_bat_mph=(63.0, 88.0),
        psi_deg={"baseball": (0.0, 30.0)},
        noise={"v_bat_mph": 0.5, "v_ball_mph": 0.5, "theta_deg": 0.5, "omega_rpm": 75.0},
        e_x_scatter=0.0,
    )
    ds = simulate(settings, load_balls(ROOT / "config" / "balls.csv"), load_bats(bats_csv))
    rows = []
    for i in range(ds.sizes["impact"]):
        row = {"impact_id": f"{prefix}{i + 1:02d}", "bat": bat, "ball": "baseball"}
        for col, var, unit, digits in COLUMNS:
            row[col] = f"{float(ds[var].values[i]) / unit:.{digits}f}"
            row[f"{col}_err"] = f"{float(ds[var + '_err'].values[i]) / unit:g}"
        rows.append(row)
    return rows


def write_rows(path: Path, rows: list[dict]) -> None:
    """Write the rows as the committed examples are (comma-separated, LF line ends)."""
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, HEADER, lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
