"""Judge a robustness study's coverage.csv by issue 22's criterion and print one markdown row per grid point.

Criterion: every 95 % interval covers in 93-97 % within two binomial errors (the combined
interval where the replicates draw their calibration and the quantity has a systematic, the
statistical one otherwise), and |bias| <= 0.25 of the standard error.

Usage: ``.venv/bin/python bench/robustness_table.py [results/studies/robustness/coverage.csv]``
"""

from __future__ import annotations

import sys

import numpy as np
import pandas as pd

LOW, HIGH, BIAS = 0.93, 0.97, 0.25


def label(r) -> str:
    """Quantity, ball and bat of a row, short."""
    bat = f" {r.bat}" if isinstance(r.bat, str) and r.bat else ""
    return f"{r.quantity} {r.ball}{bat}"


def judge(d: pd.DataFrame) -> pd.DataFrame:
    """Per row: the judged coverage, its error, whether it fails, and the bias test."""
    d = d[np.isfinite(d["n_replicates"].astype(float))].copy()
    combined = np.isfinite(d["coverage_95_combined"].astype(float))
    d["judged"] = np.where(combined, d["coverage_95_combined"], d["coverage_95"]).astype(float)
    d["judged_err"] = np.where(combined, d["coverage_95_combined_err"], d["coverage_95_err"]).astype(float)
    d["cover_fail"] = (d["judged"] + 2 * d["judged_err"] < LOW) | (d["judged"] - 2 * d["judged_err"] > HIGH)
    d["bias_fail"] = d["bias_over_se"].abs() > BIAS
    return d


def main() -> None:
    """Print the table and the totals."""
    path = sys.argv[1] if len(sys.argv) > 1 else "results/studies/robustness/coverage.csv"
    d = judge(pd.read_csv(path))
    keys = ["pixel_noise_px", "impacts_per_bat", "contact_ms"]
    print(
        "| noise (px) | impacts per bat | contact (ms) | lowest 95 % judged"
        " | outside 93-97 % by > 2 binomial errors | largest \\|bias\\| / SE | \\|bias\\| > 0.25 |"
    )
    print("|---|---|---|---|---|---|---|")
    for key, g in d.groupby(keys):
        low = g.loc[g["judged"].idxmin()]
        big = g.loc[g["bias_over_se"].abs().idxmax()]
        fails = "; ".join(f"{label(r)} {r.judged:.3f}" for r in g[g["cover_fail"]].itertuples()) or "none"
        nb = int(g["bias_fail"].sum())
        print(
            f"| {key[0]:g} | {key[1]:g} | {key[2]:g} | {low.judged:.3f} ({label(low)}) | {fails} |"
            f" {big.bias_over_se:+.2f} ({label(big)}) | {nb} of {len(g)} |"
        )
    n = len(d)
    print(
        f"\n{n} entries at {d.groupby(keys).ngroups} points: {int(d['cover_fail'].sum())} outside 93-97 % by more than"
        f" two binomial errors, {int(d['bias_fail'].sum())} with |bias| > {BIAS} SE"
        f" ({int((d['bias_over_se'].abs() - 2 * d['bias_over_se_err'] > BIAS).sum())} of them by more than two errors);"
        f" judged coverage {d['judged'].min():.3f}-{d['judged'].max():.3f}"
    )


if __name__ == "__main__":
    main()
