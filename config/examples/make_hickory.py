"""Regenerate hickory_impacts.csv, the example of a bat measured in a lab's terms (run once; output is committed).

The bat sheet hickory_bats.csv is in the lab convention of ASTM F2398 / F2219 (length 34 in,
weight 32 oz, balance point 23.0 in from the knob, MOI 11200 oz in^2 about the pivot 6 in
from the knob, impact 6 in from the barrel tip, barrel diameter 2.6 in, Iz 11.0 oz in^2);
ballbat converts it to the paper's convention (M 32 oz, I0 = 11200 - 32 * 17^2 = 1952 oz in^2,
b = 34 - 6 - 23 = 5 in, R = 1.3 in). 30 baseball impacts are drawn with ballbat's forward
model on that bat (Sec. III; true e_x = 0.455, e_y = 0.45) plus the default measurement
noise and rounded as a lab would record them.

    .venv/bin/python config/examples/make_hickory.py [OUT]   (OUT: another path, to compare)
"""

import sys
from pathlib import Path

from lab_example import baseball_rows, write_rows

HERE = Path(__file__).resolve().parent
OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "hickory_impacts.csv"
#: The truth the impacts are drawn with.
E_X_TRUE = 0.455

write_rows(OUT, baseball_rows("hickory", HERE / "hickory_bats.csv", e_x=E_X_TRUE, seed=20261126, prefix="HK"))
