"""Benchmark: a study's truth job, its memory plan against its measured peak (issue 40).

The truth job of one sweep point holds the design's large noise-free experiment; its size is
``StudySettings.truth_counts`` (``ballbat.studies.sweeps.truth_counts``) and its memory plan, what
Snakemake schedules it with, ``StudySettings.truth_mem_mb``. For each design below a child
process runs the truth job's code (``studies.truth_dataset`` of one point) and reports its peak
resident memory. Target: the plan covers the peak and is within 1.5 times it.

Designs: the shipped calibration study (20/19/19 baseball, 13/13/12/12 softball impacts per
bat); an unbalanced design of 6 and 60 impacts per bat (the softball bat swung with softballs
only), at the default ``truth_impacts`` and at 2000; a balanced design of 30 per bat (the truth
holds 10 000 impacts per pair).

Run: ``.venv/bin/python bench/bench_truth_memory.py [design ...]`` (about 2-3 CPU minutes per
design). Prints a table.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time

_UNBALANCED = {
    "baseball": {"wood": 6, "metal_rough": 60, "metal_smooth": 6},
    "softball": {"wood": 60, "metal_rough": 6, "metal_smooth": 60, "softball_composite": 6},
}

#: name -> (impacts per ball and bat, truth_impacts); None: as the shipped calibration study has it.
DESIGNS = {
    "calibration": (None, None),
    "unbalanced_6_60": (_UNBALANCED, None),
    "unbalanced_T2000": (_UNBALANCED, 2000),
    "balanced_30": (
        {
            "baseball": {"wood": 30, "metal_rough": 30, "metal_smooth": 30},
            "softball": {"wood": 30, "metal_rough": 30, "metal_smooth": 30, "softball_composite": 30},
        },
        None,
    ),
}
CHILD = """
import json, resource, sys, time
from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.studies.settings import StudySettings
from ballbat.studies.truth import truth_dataset
impacts, truth_impacts = json.loads(sys.argv[1])
cfg = load_config()
if impacts is not None:
    cfg["datasets"]["synthetic"]["synthetic"]["impacts"] = impacts
if truth_impacts is not None:
    cfg["studies"]["calibration"]["truth_impacts"] = truth_impacts
s = StudySettings.from_config(cfg, "calibration")
t0 = time.perf_counter()
truth_dataset(s, load_balls("config/balls.csv"), load_bats("config/bats.csv"), points=[0])
dt = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"k": s.truth_counts(0)[0], "impacts": s.truth_size(0), "plan_mb": s.truth_mem_mb(0),
                  "runtime_plan_min": s.truth_runtime_min(0), "peak_mb": peak, "seconds": dt}))
"""


def measure(design: tuple) -> dict:
    """Run one design's truth job in a child process; return its scale, size, plans, peak (MB) and time."""
    out = subprocess.run([sys.executable, "-c", CHILD, json.dumps(design)], check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(names: list[str]) -> None:
    """Print the plan against the measured peak for each design."""
    head = ("design", "k", "impacts", "plan MB", "peak MB", "plan/peak", "s", "plan min")
    print(f"{head[0]:<17} " + " ".join(f"{h:>9}" for h in head[1:]))
    for name in names or list(DESIGNS):
        t0 = time.perf_counter()
        r = measure(DESIGNS[name])
        ratio = r["plan_mb"] / r["peak_mb"]
        verdict = "ok" if 1.0 <= ratio <= 1.5 else "OUTSIDE 1-1.5"
        print(
            f"{name:<17} {r['k']:>9} {r['impacts']:>9} {r['plan_mb']:>9} {r['peak_mb']:>9.0f} {ratio:>9.2f} "
            f"{r['seconds']:>9.0f} {r['runtime_plan_min']:>9}  {verdict} ({time.perf_counter() - t0:.0f} s wall)"
        )


if __name__ == "__main__":
    main(sys.argv[1:])
