"""Benchmark of replicate studies (issue 12).

1. The shipped ``calibration`` study (1000 replicates of the paper-sized experiment, the whole
   chain: simulate, render and reduce the camera tracks, normalise, reconstruct, every Sec. IV
   fit and the eta^2 fit, plus the design's noise-free truth) through ``snakemake -c2`` in a
   fresh copy of the repository. Target: under 5 minutes.
2. Cost against replicates: one batch of 10, 40 and 160 replicates (target: linear).
3. Memory against replicates: the peak resident memory of a process running one batch of
   10, 40 and 160 replicates (target: flat).

Run: ``.venv/bin/python bench/bench_study.py`` (about 5 minutes on 2 cores). Prints a table.
"""

from __future__ import annotations

import csv
import io
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench_workflow import ROOT, fresh_copy  # bench/ is on the path when run as a script

from ballbat.pipeline.ncio import read_table_csv

CHILD = """
import resource, sys, time
from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.studies import batch as study_batch
from ballbat.studies.settings import StudySettings
n = int(sys.argv[1])
cfg = load_config()
cfg["studies"]["calibration"]["batch_size"] = n
s = StudySettings.from_config(cfg, "calibration")
balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
study_batch.run(s, 0, balls, bats)  # warm-up of the imports and caches: one batch
t0 = time.perf_counter()
ds = study_batch.run(s, 1, balls, bats)
dt = time.perf_counter() - t0
print(dt, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, ds.sizes["replicate"])
"""


def workflow_time() -> tuple[float, float, int, list[dict]]:
    """Wall time of the calibration study through Snakemake (-c2), the largest job's RSS (MB), batches, coverage."""
    with tempfile.TemporaryDirectory() as tmp:
        wd = fresh_copy(Path(tmp))
        cmd = [sys.executable, "-m", "snakemake", "-c2", "results/studies/calibration/coverage.csv"]
        t0 = time.perf_counter()
        subprocess.run(cmd, cwd=wd, check=True, capture_output=True)
        dt = time.perf_counter() - t0
        rss = []
        bench_dir = wd / "results" / "studies" / "calibration" / "benchmarks"
        for tsv in bench_dir.glob("*.tsv"):  # the batches, the truth and the aggregate
            with open(tsv) as fh:
                rss += [float(r["max_rss"]) for r in csv.DictReader(fh, delimiter="\t")]
        # the table ends in its check line (pipeline.checked): read_table_csv verifies and drops it
        table = list(
            csv.DictReader(io.StringIO(read_table_csv(wd / "results" / "studies" / "calibration" / "coverage.csv")))
        )
        return dt, max(rss), len(list(bench_dir.glob("batch*.tsv"))), table


def batch(n: int) -> tuple[float, float]:
    """Seconds and peak RSS (MB) of a process running a batch of ``n`` replicates (after one warm-up batch)."""
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(n)], cwd=ROOT, check=True, capture_output=True, text=True
    ).stdout.split()
    return float(out[0]), float(out[1]) / 1024


def main() -> None:
    """Print the benchmark table."""
    dt, rss, nb, table = workflow_time()
    print("calibration study: 1000 replicates, snakemake -c2, fresh copy")
    print(f"  wall time                      {dt:7.1f} s   (target < 300 s: {'yes' if dt < 300 else 'NO'})")
    print(f"  batches                        {nb:7d}")
    print(f"  largest job's max RSS          {rss:7.0f} MB")
    print("  coverage (95 % target 93-97 %, spread / SE target 0.9-1.1):")
    for r in table:
        name = " ".join(x for x in (r["quantity"], r["ball"], r["bat"]) if x)
        c95, e95 = 100 * float(r["coverage_95"]), 100 * float(r["coverage_95_err"])
        c68 = 100 * float(r["coverage_68"])
        ok = 93 <= c95 <= 97 and 0.9 <= float(r["spread_over_se"]) <= 1.1
        print(
            f"    {name:38s} 95 %: {c95:5.1f} +- {e95:3.1f}  68 %: {c68:5.1f}"
            f"  spread/SE {float(r['spread_over_se']):5.2f}  bias/SE {float(r['bias_over_se']):+5.2f}"
            f"  {'' if ok else '<- outside'}"
        )
    print("one batch in one process (after a warm-up batch)")
    rows = [(n, *batch(n)) for n in (10, 40, 160)]
    for n, t, m in rows:
        print(f"  {n:4d} replicates   {t:7.2f} s   {1e3 * t / n:6.0f} ms/replicate   peak RSS {m:6.0f} MB")
    print(f"  cost ratio 160/10 per replicate: {rows[2][1] / 160 / (rows[0][1] / 10):.2f} (linear: 1)")
    print(f"  memory ratio 160/10: {rows[2][2] / rows[0][2]:.2f} (flat: 1)")


if __name__ == "__main__":
    main()
