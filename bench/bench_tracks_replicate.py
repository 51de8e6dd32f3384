"""CPU per replicate of the stages after render, on a replicate study's tracks (issue 39).

    PYTHONPATH=src .venv/bin/python bench/bench_tracks_replicate.py [replicates] [repeats] [study]

Renders the tracks of the first ``replicates`` (default 4) replicates of ``study`` (default
``calibration``: 108 impacts each) once, with the settings and seeds a replicate uses
(:func:`ballbat.studies.replicates.chain_settings`), then runs the stages on them as the
replicate does (the same functions as the workflow's rules): reduce (the track fits, the
cross-checks), normalize, reconstruct, fit_ex. Prints each stage's CPU time per replicate,
the best of ``repeats`` (default 5) passes over the replicates, and, for reduce, the track fits
and the cross-checks apart. Read it as a comparison made in the same minute: the machine is shared.
"""

from __future__ import annotations

import dataclasses
import sys
import time

from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.stages import fit_ex, normalize, reconstruct, reduce, render, simulate
from ballbat.studies.replicates import chain_settings, replicate_seeds
from ballbat.studies.settings import StudySettings
from ballbat.systematics import has_shifts


def _best(fn, inputs, repeats: int) -> float:
    """Best CPU seconds of ``repeats`` passes of ``fn`` over ``inputs`` (one warm-up pass)."""
    for args in inputs:
        fn(*args)
    best = float("inf")
    for _ in range(repeats):
        t = time.process_time()
        for args in inputs:
            fn(*args)
        best = min(best, time.process_time() - t)
    return best


def main(n: int = 4, repeats: int = 5, study: str = "calibration") -> None:
    """Time the stages after render on ``n`` replicates of ``study``; print ms of CPU per replicate."""
    s = StudySettings.from_config(load_config(), study)
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    chains = []
    for rep in range(n):
        cs = chain_settings(s, s.point_dataset(0), replicate_seeds(s.seed, rep), f"render (replicate {rep})")
        tracks = render.render(cs.render, simulate.run(cs.synthetic, balls, bats), balls)
        chains.append((cs, tracks))
    src = [reduce.run(cs.reduce, tr, balls, bats) for cs, tr in chains]
    norm = [normalize.run(cs.normalize, d) for (cs, _), d in zip(chains, src, strict=True)]
    rec = [reconstruct.run(cs.reconstruct, d, balls, bats) for (cs, _), d in zip(chains, norm, strict=True)]
    fits = [dataclasses.replace(cs.fit_ex, systematic=has_shifts(d)) for (cs, _), d in zip(chains, src, strict=True)]
    reds = [reduce.reduce_tracks(tr, cs.reduce.cameras, cs.reduce.rig, cs.reduce.options) for cs, tr in chains]
    rows = [
        ("reduce (with cross-checks)", reduce.run, [(cs.reduce, tr, balls, bats) for cs, tr in chains]),
        (
            "  of which: the track fits",
            reduce.reduce_tracks,
            [(tr, cs.reduce.cameras, cs.reduce.rig, cs.reduce.options) for cs, tr in chains],
        ),
        (
            "  of which: the cross-checks",
            reduce.cross_check,
            [(red, balls, bats, cs.reduce.where) for (cs, _), red in zip(chains, reds, strict=True)],
        ),
        ("normalize", normalize.run, [(cs.normalize, d) for (cs, _), d in zip(chains, src, strict=True)]),
        (
            "reconstruct",
            reconstruct.run,
            [(cs.reconstruct, d, balls, bats) for (cs, _), d in zip(chains, norm, strict=True)],
        ),
        ("fit_ex", fit_ex.fit, list(zip(fits, rec, strict=True))),
    ]
    impacts = src[0].sizes["impact"]
    print(f"{n} replicates of study {study!r} ({impacts} impacts each); CPU ms per replicate, best of {repeats}")
    total = 0.0
    for label, fn, inputs in rows:
        ms = _best(fn, inputs, repeats) / n * 1e3
        total += 0.0 if label.startswith(" ") else ms
        print(f"{label:<30} {ms:8.1f}")
    print(f"{'reduce to fit_ex, in all':<30} {total:8.1f}")


if __name__ == "__main__":
    args = sys.argv[1:]
    main(
        int(args[0]) if args else 4,
        int(args[1]) if len(args) > 1 else 5,
        args[2] if len(args) > 2 else "calibration",
    )
