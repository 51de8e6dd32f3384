"""Replicate study of the contact time (issue 22): e_x and implied e_y when contacts are short or long.

The default ``synthetic`` dataset (108 impacts rendered as camera tracks and reduced) with the
renderer's contact time drawn from a chosen range, ``N`` replicates per range through the
study's own in-memory functions (``ballbat.studies.batch.run``, the design's truth from
``population_truth``, ``coverage``), in one process. Prints, per quantity (e_x per bat and
pooled, the implied e_y), the bias over the standard error and the 95 % coverage, each with
its binomial or standard error. Targets: |bias| <= 0.25 SE, coverage 93-97 %.

The design's truth (pooled e_x, implied e_y) comes from 3000 noise-free impacts per ball and
bat by default (``--truth-impacts``; the shipped study's 10000 take about 4 minutes alone).

Run: ``nice -n 10 .venv/bin/python bench/bench_contact.py 300 0.5-0.7 0.85-1.0`` (about 0.5 s
per replicate, 1 minute for the truth, on a loaded machine). ``--label`` names the run.
"""

from __future__ import annotations

import argparse
import time

from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.studies import batch as study_batch
from ballbat.studies.coverage import combine, coverage
from ballbat.studies.settings import StudySettings
from ballbat.studies.truth import population_truth

QUANTITIES = ("e_x", "e_x_pooled", "e_y_implied")


def run(replicates: int, contact_ms: tuple[float, float], seed: int, truth_impacts: int) -> tuple[list[dict], float]:
    """Coverage rows of the quantities for one contact range, and the seconds taken."""
    cfg = load_config()
    cfg["studies"]["calibration"].update(
        replicates=replicates, batch_size=replicates, seed=seed, truth_impacts=truth_impacts
    )
    cfg["datasets"][cfg["studies"]["calibration"]["dataset"]]["render"]["contact_ms"] = list(contact_ms)
    s = StudySettings.from_config(cfg, "calibration")
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    t0 = time.perf_counter()
    reps = combine([study_batch.run(s, 0, balls, bats)])
    cov = coverage(reps, [population_truth(s, 0, balls, bats)])
    dt = time.perf_counter() - t0
    rows = []
    for j, name in enumerate(cov["quantity_name"].values.astype(str)):
        if name not in QUANTITIES:
            continue
        rows.append(
            {
                "quantity": name,
                "ball": str(cov["ball"].values[j]),
                "bat": str(cov["bat"].values[j]),
                **{k: float(cov[k].values[0, j]) for k in ("bias_over_se", "bias_over_se_err", "coverage_95")},
                "coverage_95_err": float(cov["coverage_95_err"].values[0, j]),
                "n": int(cov["n_replicates"].values[0, j]),
            }
        )
    return rows, dt


def main() -> None:
    """Print one table per contact range."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("replicates", type=int)
    ap.add_argument("ranges", nargs="+", help="contact time ranges in ms, e.g. 0.5-0.7")
    ap.add_argument("--seed", type=int, default=20261125)
    ap.add_argument("--label", default="")
    ap.add_argument("--truth-impacts", type=int, default=3000, help="of the design's truth (the study's: 10000)")
    a = ap.parse_args()
    for rng in a.ranges:
        lo, hi = (float(v) for v in rng.split("-"))
        rows, dt = run(a.replicates, (lo, hi), a.seed, a.truth_impacts)
        print(f"\n{a.label} contact {lo}-{hi} ms, {a.replicates} replicates, {dt:.0f} s")
        print("| quantity | ball | bat | bias / SE | 95 % coverage (%) |")
        print("|---|---|---|---|---|")
        for r in rows:
            flag = "" if abs(r["bias_over_se"]) <= 0.25 and 0.93 <= r["coverage_95"] <= 0.97 else " **"
            bias = f"{r['bias_over_se']:+.2f} +- {r['bias_over_se_err']:.2f}"
            cov = f"{100 * r['coverage_95']:.1f} +- {100 * r['coverage_95_err']:.1f}{flag}"
            print(f"| {r['quantity']} | {r['ball']} | {r['bat']} | {bias} | {cov} |", flush=True)


if __name__ == "__main__":
    main()
