"""Profile of a study's truth job: where its time and memory go (issue 39).

Runs ``ballbat.studies.truth.run`` for one sweep point of a shipped study (default
``calibration``, point 0) in this process, as the rule ``study_truth_point`` does, and prints its
CPU and wall time, the peak resident memory and the top functions by cumulative time (cProfile).

Run: ``.venv/bin/python bench/profile_truth.py [study] [point] [--plain]``.
"""

from __future__ import annotations

import cProfile
import io
import pstats
import resource
import sys
import time

from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.studies import truth
from ballbat.studies.settings import StudySettings


def main(study: str = "calibration", point: int = 0, plain: bool = False) -> None:
    """Profile the truth job of ``study`` at ``point``."""
    s = StudySettings.from_config(load_config(), study)
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    prof = cProfile.Profile()
    t0, c0 = time.perf_counter(), time.process_time()
    if not plain:
        prof.enable()
    truth.run(s, balls, bats, points=[point])
    prof.disable()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(
        f"truth of study {study!r}, point {point}: {s.truth_size(point)} impacts, {cpu:.1f} s CPU, "
        f"{wall:.1f} s wall, peak RSS {rss:.0f} MB ({'no profiler' if plain else 'under cProfile'})"
    )
    if not plain:
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("cumulative").print_stats(40)
        print(out.getvalue())


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--plain"]
    main(args[0] if args else "calibration", int(args[1]) if len(args) > 1 else 0, "--plain" in sys.argv)
