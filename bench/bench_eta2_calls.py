"""Calls of Stronge's model and CPU time of the eta^2 fits in calibration replicates (issue 39).

Runs ``N`` replicates (default 5) of the calibration study as its batch job does
(``ballbat.studies.batch.run``, batch 1) after one warm-up replicate and prints, per
replicate, how many times :func:`ballbat.stronge.model.stronge_ex` is called and from where
(the function that called it), and the CPU time (``time.process_time``) of the eta^2 fits
(``_eta2``: the measured fit and the noise-free truth of each ball). Repeat the run
and read the smallest time when the machine is shared.

Run: ``.venv/bin/python bench/bench_eta2_calls.py [N]``.
"""

from __future__ import annotations

import collections
import sys
import time
import traceback

from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.stronge import analysis, fit, model
from ballbat.studies import batch as study_batch
from ballbat.studies import replicates
from ballbat.studies.settings import StudySettings

CALLS: collections.Counter[str] = collections.Counter()
SPENT = [0.0]


def _counted(fn):
    def wrapper(psi, contact):
        CALLS[traceback.extract_stack(limit=2)[0].name] += 1
        return fn(psi, contact)

    return wrapper


def _timed(fn):
    def wrapper(*args, **kwargs):
        t0 = time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            SPENT[0] += time.process_time() - t0

    return wrapper


def main(n: int = 5) -> None:
    """Run ``n`` calibration replicates; print the model's calls by caller and the eta^2 fits' CPU time."""
    cfg = load_config()
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    cfg["studies"]["calibration"]["batch_size"] = 1
    study_batch.run(StudySettings.from_config(cfg, "calibration"), 0, balls, bats)  # warm-up
    cfg["studies"]["calibration"]["batch_size"] = n
    counted = _counted(model.stronge_ex)
    fit.stronge_ex = analysis.stronge_ex = counted
    replicates._eta2 = _timed(replicates._eta2)
    study_batch.run(StudySettings.from_config(cfg, "calibration"), 1, balls, bats)
    print(f"{n} calibration replicates: stronge_ex calls per replicate, by caller")
    for name, k in CALLS.most_common():
        print(f"  {name:<24} {k / n:6.1f}")
    print(f"  {'total':<24} {sum(CALLS.values()) / n:6.1f}")
    print(f"eta^2 fits (value and truth): {SPENT[0] / n * 1e3:.1f} ms CPU per replicate")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
