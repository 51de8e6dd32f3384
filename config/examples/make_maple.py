"""Regenerate maple_impacts.csv, the example measured dataset (run once; output is committed).

31 baseball impacts on a maple bat that is not in the paper (maple_bats.csv): 30 drawn with
ballbat's forward model (Sec. III, true e_x = 0.42, e_y = 0.45, bat speed 63-88 mph, psi
0-30 deg) plus the default measurement noise, rounded as a lab would record them, and one
impact whose spin was mis-read (18500 rpm for 1850): its psi cannot be reconstructed, so
the workflow excludes it and says why.

    .venv/bin/python config/examples/make_maple.py [OUT]   (OUT: another path, to compare)
"""

import sys
from pathlib import Path

from lab_example import baseball_rows, write_rows

HERE = Path(__file__).resolve().parent
OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "maple_impacts.csv"

rows = baseball_rows("maple", HERE / "maple_bats.csv", e_x=0.42, seed=20240611, prefix="MP")
glitch = dict(rows[-1], impact_id="MP31", v_bat_mph="71.2", v_ball_mph="60.4", theta_deg="7.9", omega_rpm="18500")
write_rows(OUT, [*rows, glitch])
