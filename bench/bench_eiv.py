"""Errors in variables (issue 22): coverage and bias of the moment-corrected fits against the plain ones.

For each set-up (the shipped calibration; 5 px tracking noise at the paper's size; 3.5 px
with 60 impacts per bat) it runs replicate experiments through the study's chain
(:func:`ballbat.studies.batch.run`) twice on the same replicates: with the fits as they
were (weighted least squares, which the abscissa's noise attenuates) and with the
moment-corrected fits (``linefit.eiv_line``, ``fitting.implied_e_y``). Each replicate's
experiment and tracks are simulated once and reused by the second pass. The design's truth
(:func:`ballbat.studies.truth.population_truth`) is computed once per set-up, with
``truth_impacts`` noise-free impacts per ball and bat (3000 here: it scatters by about 0.1
of a replicate's standard error, docs/studies.md).

Run: ``nice -n 10 .venv/bin/python bench/bench_eiv.py [replicates] [setup ...]`` (one process;
about 15 minutes for the three set-ups at 300 / 300 / 200 replicates on a shared machine). Prints, per set-up,
quantity and estimator, the 95 % coverage with its binomial error and the bias / SE, and
the mean bias / SE of e_x per bat.
"""

from __future__ import annotations

import sys
import time
from contextlib import contextmanager
from dataclasses import replace
from unittest import mock

import numpy as np

from ballbat import chain, fitting
from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.studies import batch as study_batch
from ballbat.studies.coverage import coverage
from ballbat.studies.settings import StudySettings
from ballbat.studies.sweeps import point_dataset
from ballbat.studies.truth import population_truth

#: name -> (replicates, [(sweep parameter, value), ...])
SETUPS = {
    "calibration": (300, []),
    "px5": (300, [("pixel_noise_px", 5.0)]),
    "px3.5_n60": (200, [("pixel_noise_px", 3.5), ("impacts_per_bat", 60)]),
}


@contextmanager
def plain_fits():
    """The fits as before the correction: weighted least squares, e_y's sums uncorrected, dof n - 1."""
    real = fitting.fit_line

    def fit_line(*args, **kw):
        kw["errors_in_variables"] = False
        return real(*args, **kw)

    def zeros(jx, jy, sigma):
        return np.zeros(len(jx)), np.zeros(len(jx))

    with mock.patch.object(fitting, "fit_line", fit_line), mock.patch.object(fitting, "_noise_moments", zeros):
        yield


def settings_for(cfg: dict, name: str) -> StudySettings:
    """The calibration study's settings at set-up ``name`` (one batch, 3000-impact truth)."""
    reps, sets = SETUPS[name]
    s = StudySettings.from_config(cfg, "calibration")
    ds = s.dataset
    for par, val in sets:
        ds = point_dataset(ds, par, val)
    return replace(s, dataset=ds, replicates=reps, batch_size=reps, truth_impacts=3000)


def table(cov, label: str) -> list[str]:
    """Lines of the coverage table of one estimator, and the mean bias / SE of e_x per bat."""
    lines = []
    names = cov["quantity"].values.astype(str)
    z_ex = []
    for j, q in enumerate(names):
        c, e = 100 * cov["coverage_95"].values[0, j], 100 * cov["coverage_95_err"].values[0, j]
        b, be = cov["bias_over_se"].values[0, j], cov["bias_over_se_err"].values[0, j]
        sp = cov["spread_over_se"].values[0, j]
        lines.append(f"  {label:6s} {q:45s} {c:5.1f} ± {e:3.1f} %   bias/SE {b:+.3f} ± {be:.3f}   spread/SE {sp:.2f}")
        if q.startswith("e_x:"):
            z_ex.append(b)
    z_ex = np.array(z_ex)
    neg = f"{np.sum(z_ex < 0)} of {z_ex.size} negative"
    lines.append(f"  {label:6s} e_x per bat: mean bias/SE {z_ex.mean():+.3f}, {neg}")
    return lines


def main() -> None:
    """Run the set-ups named on the command line (all by default) and print their tables."""
    args = sys.argv[1:]
    reps = int(args.pop(0)) if args and args[0].isdigit() else None
    names = args or list(SETUPS)
    cfg = load_config()
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    cache: dict = {}
    real_source = chain.source

    def cached_source(settings, balls_, bats_):
        seeds = (settings.synthetic.seed, settings.render.seed if settings.render else None)
        if seeds not in cache:
            cache[seeds] = real_source(settings, balls_, bats_)
        return cache[seeds]

    for name in names:
        s = settings_for(cfg, name)
        if reps:
            s = replace(s, replicates=reps, batch_size=reps)
        cache.clear()
        t0 = time.perf_counter()
        truth = [population_truth(s, 0, balls, bats)]
        t_truth = time.perf_counter() - t0
        out = [f"{name}: {s.replicates} replicates (truth {t_truth:.0f} s)"]
        with mock.patch.object(chain, "source", cached_source):
            for label in ("before", "after"):
                t0 = time.perf_counter()
                if label == "before":
                    with plain_fits():
                        rep = study_batch.run(s, 0, balls, bats)
                else:
                    rep = study_batch.run(s, 0, balls, bats)
                dt = time.perf_counter() - t0
                cov = coverage(rep, truth)
                out += [*table(cov, label), f"  {label}: {dt:.0f} s"]
        print("\n".join(out), flush=True)


if __name__ == "__main__":
    main()
