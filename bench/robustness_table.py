"""Judge a robustness study's coverage.csv by issue 22's criterion and print one markdown row per grid point.

Criterion: every 95 % interval covers in 93-97 % within two binomial errors, and |bias| <= 0.25
of the standard error. Where the replicates draw their calibration, two intervals are judged:
the combined one (statistical and systematic in quadrature, around the value) and the
statistical one around the value with the drawn calibration's first-order effect taken out
(``coverage_95_calibrated``: what the statistical error claims to cover); the bias is judged
the same way (``bias_over_se_calibrated``), since the draw's own spread, up to 4 statistical
errors at 1 px, would otherwise hide any bias. Without a drawn calibration: the statistical
interval and bias around the value.

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


def _either(d: pd.DataFrame, first: str, other: str) -> np.ndarray:
    a = d[first].astype(float) if first in d else pd.Series(np.nan, index=d.index)
    return np.where(np.isfinite(a), a, d[other].astype(float))


def _outside(c: pd.Series, err: pd.Series) -> pd.Series:
    return ((c + 2 * err < LOW) | (c - 2 * err > HIGH)).fillna(False)


def judge(d: pd.DataFrame) -> pd.DataFrame:
    """Per row: the judged statistical and combined coverages, whether they fail, and the bias test."""
    d = d[np.isfinite(d["n_replicates"].astype(float))].copy()
    d["stat"] = _either(d, "coverage_95_calibrated", "coverage_95")
    d["stat_err"] = _either(d, "coverage_95_calibrated_err", "coverage_95_err")
    d["comb"] = d["coverage_95_combined"].astype(float)
    d["comb_err"] = d["coverage_95_combined_err"].astype(float)
    d["stat_fail"] = _outside(d["stat"], d["stat_err"])
    d["comb_fail"] = _outside(d["comb"], d["comb_err"])
    d["cover_fail"] = d["stat_fail"] | d["comb_fail"]
    d["bias"] = _either(d, "bias_over_se_calibrated", "bias_over_se")
    d["bias_err"] = _either(d, "bias_over_se_calibrated_err", "bias_over_se_err")
    d["bias_fail"] = d["bias"].abs() > BIAS
    d["bias_fail_2err"] = d["bias"].abs() - 2 * d["bias_err"] > BIAS
    return d


def main() -> None:
    """Print the table and the totals."""
    path = sys.argv[1] if len(sys.argv) > 1 else "results/studies/robustness/coverage.csv"
    d = judge(pd.read_csv(path, comment="#"))
    keys = ["pixel_noise_px", "impacts_per_bat", "contact_ms"]
    print(
        "| noise (px) | impacts per bat | contact (ms) | lowest statistical 95 % | lowest combined 95 %"
        " | outside 93-97 % by > 2 binomial errors | largest \\|bias\\| / SE | \\|bias\\| > 0.25 |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for key, g in d.groupby(keys):
        low = g.loc[g["stat"].idxmin()]
        lowc = g.loc[g["comb"].idxmin()] if np.isfinite(g["comb"]).any() else None
        big = g.loc[g["bias"].abs().idxmax()]
        fails = [f"{label(r)} stat. {r.stat:.3f}" for r in g[g["stat_fail"]].itertuples()]
        fails += [f"{label(r)} comb. {r.comb:.3f}" for r in g[g["comb_fail"]].itertuples()]
        comb = "" if lowc is None else f"{lowc.comb:.3f} ({label(lowc)})"
        print(
            f"| {key[0]:g} | {key[1]:g} | {key[2]:g} | {low.stat:.3f} ({label(low)}) | {comb} |"
            f" {'; '.join(fails) or 'none'} | {big.bias:+.2f} ± {big.bias_err:.2f} ({label(big)}) |"
            f" {int(g['bias_fail'].sum())} of {len(g)} |"
        )
    n = len(d)
    if "n_refused" in d:
        refused = d.groupby(keys)["n_refused"].max()
        print(f"\nreplicates refused by the data's checks: {int(refused.sum())} at {int((refused > 0).sum())} points")
    print(
        f"\n{n} entries at {d.groupby(keys).ngroups} points: {int(d['stat_fail'].sum())} statistical and"
        f" {int(d['comb_fail'].sum())} combined 95 % intervals outside 93-97 % by more than two binomial errors;"
        f" {int(d['bias_fail'].sum())} with |bias| > {BIAS} SE ({int(d['bias_fail_2err'].sum())} of them by more"
        f" than two errors); statistical coverage {d['stat'].min():.3f}-{d['stat'].max():.3f},"
        f" combined {d['comb'].min():.3f}-{d['comb'].max():.3f}; bias {d['bias'].min():+.2f} to {d['bias'].max():+.2f}"
    )


if __name__ == "__main__":
    main()
