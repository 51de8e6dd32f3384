"""Profile of a replicate study: where one replicate's time goes, by stage and by function (issue 39).

Runs ``N`` replicates (default 10) of a shipped study (default ``calibration``) in this
process, exactly as its batch job does (``ballbat.studies.batch.run``), after one warm-up
replicate, and prints:

1. CPU time per replicate of each stage of the chain (simulate, render, reduce with its
   cross-checks, normalize, reconstruct, fit_ex, the eta^2 fits, the assembly of the batch's
   Dataset), measured by timing the stage functions themselves;
2. the top functions by their own time and by cumulative time (cProfile).

Run: ``.venv/bin/python bench/profile_study.py [N] [study] [point] [--plain]`` (about N x 0.1-0.3 s).
Read the stage table as shares when the machine is busy. ``point``: the sweep point whose first
replicates are run (default 0; the robustness grid's costliest are 24-26: 5 px, 60 impacts per bat).
``--plain``: without cProfile (the stage timers only, no function tables): the CPU time per
replicate as a batch job spends it.
"""

from __future__ import annotations

import cProfile
import functools
import io
import pstats
import sys
import time
from collections import defaultdict

from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.stages import fit_ex, normalize, reconstruct, reduce, render, simulate
from ballbat.studies import batch as study_batch
from ballbat.studies import replicates
from ballbat.studies.settings import StudySettings

#: (module, function name, label): the stage functions a replicate calls, timed where they are looked up.
STAGES = [
    (simulate, "run", "simulate"),
    (render, "render", "render tracks"),
    (reduce, "run", "reduce (with cross-checks)"),
    (reduce, "reduce_tracks", "  of which: the track fits"),
    (reduce, "cross_check", "  of which: the cross-checks"),
    (normalize, "run", "normalize"),
    (reconstruct, "run", "reconstruct (x2: measured, truth)"),
    (fit_ex, "fit", "fit_ex (Sec. IV fits)"),
    (replicates, "_eta2", "eta^2 fits (value and truth)"),
    (replicates, "_eta2_systematic", "eta^2 systematics"),
]

SPENT: dict[str, float] = defaultdict(float)


def _timed(fn, label):
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        t0 = time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            SPENT[label] += time.process_time() - t0

    return wrapper


def instrument() -> None:
    """Wrap every stage function of :data:`STAGES` with a CPU timer (in its own module)."""
    for module, name, label in STAGES:
        if hasattr(module, name):
            setattr(module, name, _timed(getattr(module, name), label))


def main(n: int = 10, study: str = "calibration", plain: bool = False, point: int = 0) -> None:
    """Profile ``n`` replicates of ``study`` at ``point``: the stage table and (not ``plain``) the top functions."""
    cfg = load_config()
    cfg["studies"][study]["batch_size"] = n
    s = StudySettings.from_config(cfg, study)
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    warm = StudySettings.from_config(
        {**cfg, "studies": {**cfg["studies"], study: {**cfg["studies"][study], "batch_size": 1}}}, study
    )
    study_batch.run(warm, 0, balls, bats)  # imports and caches
    instrument()
    prof = cProfile.Profile()
    t0, c0 = time.perf_counter(), time.process_time()
    if not plain:
        prof.enable()
    # the batch that starts the point (batch 1 at point 0: batch 0 warmed up)
    ds = study_batch.run(s, point * s.replicates // n + (1 if point == 0 else 0), balls, bats)
    prof.disable()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    reps = ds.sizes["replicate"]
    print(
        f"{reps} replicates of study {study!r}: {cpu / reps * 1e3:.0f} ms CPU, "
        f"{wall / reps * 1e3:.0f} ms wall per replicate ({'no profiler' if plain else 'under cProfile'})"
    )
    print(f"\n{'stage':<36} {'ms / replicate':>15} {'share':>7}")
    for _, _, label in STAGES:
        print(f"{label:<36} {SPENT[label] / reps * 1e3:>15.1f} {SPENT[label] / cpu:>7.1%}")
    top = [label for _, _, label in STAGES if not label.startswith(" ")]
    rest = cpu - sum(SPENT[label] for label in top)
    print(f"{'everything else (rows, Dataset)':<36} {rest / reps * 1e3:>15.1f} {rest / cpu:>7.1%}")
    for key, title in () if plain else (("tottime", "own time"), ("cumulative", "cumulative time")):
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats(key).print_stats(int(__import__("os").environ.get("TOPN", 15)))
        lines = out.getvalue().splitlines()
        start = next(i for i, line in enumerate(lines) if line.strip().startswith("ncalls"))
        print(f"\nTop 15 functions by {title} (seconds over {reps} replicates):")
        print("\n".join(lines[start : start + 1 + int(__import__("os").environ.get("TOPN", 15))]))


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--plain"]
    main(
        int(args[0]) if args else 10,
        args[1] if len(args) > 1 else "calibration",
        "--plain" in sys.argv,
        int(args[2]) if len(args) > 2 else 0,
    )
