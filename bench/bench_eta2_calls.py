"""Evaluations of Stronge's model and CPU time of the eta^2 fits in calibration replicates (issue 39).

Runs ``N`` replicates (default 5) of the calibration study as its batch job does
(``ballbat.studies.batch.run``, batch 1) after one warm-up replicate and prints, per
replicate and per fit (``fit_ball``: the measured value and the noise-free truth of each
ball), how many times Stronge's model is evaluated (``_solve_ex``, which both
:func:`ballbat.stronge.model.stronge_ex` and ``ImpactGeometry.e_x`` run) and from where (the
first function outside the model and the fit's residual: ``_scan_start``, MINPACK's calls
``fcn``, the sandwich's ``_jacobian``, ``_ex_at`` of the errors-in-variables step,
``finite_sample_bias``), with the impacts evaluated, and the CPU time
(``time.process_time``) of the eta^2 fits (``_eta2``). It then fits the same balls again,
``ROUNDS`` times, and prints the best CPU time per ``fit_ball`` (the least disturbed round on a
shared machine). On code from before ``ImpactGeometry`` (an exported older ``src/`` on
``PYTHONPATH``) it counts the calls of ``stronge_ex`` instead, so that before and after can be
run in alternation. Repeat the run and read the smallest time when the machine is shared.

Run: ``.venv/bin/python bench/bench_eta2_calls.py [N]``.
"""

from __future__ import annotations

import collections
import sys
import time
import traceback

import numpy as np

from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.stronge import analysis, fit, model
from ballbat.studies import batch as study_batch
from ballbat.studies import replicates
from ballbat.studies.settings import StudySettings

STRONGE_EX, SOLVE_EX = model.stronge_ex, getattr(model, "_solve_ex", None)
CALLS: collections.Counter[str] = collections.Counter()
SIZES: collections.Counter[str] = collections.Counter()
FITS: list = []
SPENT = [0.0]
#: Rounds of the second part (the same fits again), of which the best is printed.
ROUNDS = 5
#: Frames between a caller and the model's evaluation (the model's own and the fit's residual).
PASSING = {"_solve_ex", "stronge_ex", "e_x", "__call__", "wrapper"}


def _counted(fn):
    def wrapper(*args):
        caller = next(f.name for f in reversed(traceback.extract_stack(limit=8)) if f.name not in PASSING)
        CALLS[caller] += 1
        SIZES[caller] += args[0].rho.size if len(args) == 1 else np.size(args[0]) * np.size(args[1].eta2)
        return fn(*args)

    return wrapper


def _count_the_model() -> None:
    """Count every evaluation of the model (``_solve_ex``; before it existed, ``stronge_ex`` where the fits call it)."""
    if hasattr(model, "_solve_ex"):
        model._solve_ex = _counted(model._solve_ex)
        return
    counted = _counted(model.stronge_ex)
    fit.stronge_ex = analysis.stronge_ex = counted


def _fits(fn):
    def wrapper(*args, **kwargs):
        FITS.append((args, kwargs))
        return fn(*args, **kwargs)

    return wrapper


def _refit(fit_ball) -> float:
    """Best CPU time (s) per fit_ball of fitting the recorded balls again, over ROUNDS rounds."""
    best = np.inf
    for _ in range(ROUNDS):
        t0 = time.process_time()
        for args, kwargs in FITS:
            fit_ball(*args, **kwargs)
        best = min(best, (time.process_time() - t0) / len(FITS))
    return best


def _timed(fn):
    def wrapper(*args, **kwargs):
        t0 = time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            SPENT[0] += time.process_time() - t0

    return wrapper


def main(n: int = 5) -> None:
    """Run ``n`` calibration replicates; print the model's evaluations by caller and the eta^2 fits' CPU time."""
    cfg = load_config()
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    cfg["studies"]["calibration"]["batch_size"] = 1
    study_batch.run(StudySettings.from_config(cfg, "calibration"), 0, balls, bats)  # warm-up
    cfg["studies"]["calibration"]["batch_size"] = n
    fit_ball = analysis.fit_ball
    _count_the_model()
    analysis.fit_ball = _fits(fit_ball)
    replicates._eta2 = _timed(replicates._eta2)
    study_batch.run(StudySettings.from_config(cfg, "calibration"), 1, balls, bats)
    fits = len(FITS) / n
    print(f"{n} calibration replicates, {fits:.0f} fit_ball a replicate: evaluations of the model, by caller")
    print(f"  {'caller':<22} {'per replicate':>14} {'per fit_ball':>13} {'impacts each':>13}")
    for name, k in CALLS.most_common():
        print(f"  {name:<22} {k / n:14.1f} {k / n / fits:13.2f} {SIZES[name] / k:13.0f}")
    total = sum(CALLS.values())
    print(f"  {'total':<22} {total / n:14.1f} {total / n / fits:13.2f}")
    print(f"eta^2 fits (value and truth): {SPENT[0] / n * 1e3:.1f} ms CPU per replicate")
    model.stronge_ex = fit.stronge_ex = analysis.stronge_ex = STRONGE_EX  # no counting in the second part
    if hasattr(model, "_solve_ex"):
        model._solve_ex = SOLVE_EX
    print(
        f"the same {len(FITS)} fits again: {_refit(fit_ball) * 1e3:.2f} ms CPU per fit_ball (best of {ROUNDS} rounds)"
    )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
