"""Issue 36: coverage of implied e_y's interval forms and of e_x with intrinsic scatter, per set-up.

Each set-up's replicate experiments are simulated, rendered and reduced once
(:func:`ballbat.chain.source`, cached per seeds) and fitted once per estimator variant on the same
replicates: implied e_y's sandwich form (:data:`ballbat.fitting.E_Y_SANDWICH`: ``hc0k``, the
first version; ``hc2``, shipped; ``hc3``) and the e_x fits with or without the intrinsic-scatter
term (:data:`ballbat.linefit.SCATTER_TERM`; for the pooled e_x and the Eq. ratio slope, the
scatter within bats, :data:`ballbat.fitting.WITHIN_BAT_SCATTER`). Variants: ``before`` (hc0k,
no term), ``hc2`` (no term), ``after`` (hc3 and the term per bat), ``per_bat`` (hc2 and the term
per bat), ``within_redchi`` (and the term within bats for the pooled fits), ``shipped`` (and the
pooled e_x's error from the sandwich centred within bats), ``contact`` (and the contact population's
estimation error in the statistical errors, :data:`ballbat.fitting.CONTACT_POPULATION_ERROR`), ``kh``
(the Knapp-Hartung floor of the per-bat scatter fit, :data:`ballbat.linefit.KNAPP_HARTUNG_FLOOR`, without the
contact term), ``both`` and ``hc3_bat`` (the contact term and e_x per bat's error from the HC3 sandwich,
:data:`ballbat.fitting.PER_BAT_SANDWICH`: shipped); name some on the command line to run only those.
The reductions always carry the contact shifts (they are in the cached sources); only the fits use them or not.
Stronge's eta^2 is not fitted (it is not judged here).
The calibration is not drawn (statistical intervals; the combined ones need the drawn
calibration of the robustness grid).

Run: ``nice -n 10 .venv/bin/python bench/intervals_study.py REPLICATES SETUP [SETUP ...]``.
Prints, per set-up, variant and quantity (e_y_implied, tan_ratio_slope, e_x per bat,
e_x_pooled), the 95 % coverage with its binomial error, bias / SE and spread / SE.
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace
from unittest import mock

from ballbat import chain, fitting, linefit
from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.studies import batch as study_batch
from ballbat.studies import replicates
from ballbat.studies.coverage import coverage
from ballbat.studies.replicates import STUDY_QUANTITIES
from ballbat.studies.settings import StudySettings
from ballbat.studies.sweeps import point_dataset
from ballbat.studies.truth import population_truth


def _cameras(ds: dict, swing: float, spin: float) -> dict:
    ds["render"]["cameras"]["swing"]["pixel_noise_px"] = swing
    ds["render"]["cameras"]["spin"]["pixel_noise_px"] = spin
    return ds


def _narrow(ds: dict) -> dict:
    ds["synthetic"]["psi_deg"] = {"baseball": [0.0, 12.0], "softball": [0.0, 15.0]}
    return ds


def _scatter(ds: dict, tau: float) -> dict:
    ds["synthetic"]["e_x_scatter"] = tau
    return ds


#: name -> a change of the calibration study's dataset
SETUPS = {
    "calibration": lambda ds: ds,
    "lab2_cameras": lambda ds: _cameras(ds, 1.0, 3.5),
    "narrow_psi": _narrow,
    "scatter0.02": lambda ds: _scatter(ds, 0.02),
    "scatter0.01": lambda ds: _scatter(ds, 0.01),
    # the robustness grid's point where the contact population's error was shown (docs/studies.md)
    "contact0.5": lambda ds: point_dataset(ds, ("pixel_noise_px", "impacts_per_bat", "contact_ms"), (1.0, 30, 0.5)),
}

#: variant -> (E_Y_SANDWICH, SCATTER_TERM, WITHIN_BAT_SCATTER, POOLED_SANDWICH, CONTACT_POPULATION_ERROR,
#: KNAPP_HARTUNG_FLOOR, PER_BAT_SANDWICH): ``per_bat`` is the shipped form before the pooled e_x and the Eq.
#: ratio slope got the scatter within bats, ``within_redchi`` that term with the pooled e_x's error still
#: scaled by the reduced chi-square, ``shipped`` the form before the contact population's error (issue 36's
#: last step), ``contact`` and ``kh`` (the Knapp-Hartung floor) each alone, ``both`` the two, ``hc3_bat``
#: the contact term with e_x per bat's error from the HC3 sandwich (the form now shipped)
VARIANTS = {
    "before": ("hc0k", False, False, False, False, False, False),
    "hc2": ("hc2", False, False, False, False, False, False),
    "after": ("hc3", True, False, False, False, False, False),
    "per_bat": ("hc2", True, False, False, False, False, False),
    "within_redchi": ("hc2", True, True, False, False, False, False),
    "shipped": ("hc2", True, True, True, False, False, False),
    "contact": ("hc2", True, True, True, True, False, False),
    "kh": ("hc2", True, True, True, False, True, False),
    "both": ("hc2", True, True, True, True, True, False),
    "hc3_bat": ("hc2", True, True, True, True, False, True),
}


def table(cov, label: str) -> list[str]:
    """Lines of the coverage table of one variant (e_y, ratio slope, e_x)."""
    lines = []
    for j, q in enumerate(cov["quantity"].values.astype(str)):
        if q.split(":")[0] not in ("e_y_implied", "tan_ratio_slope", "e_x", "e_x_pooled"):
            continue
        c, e = 100 * cov["coverage_95"].values[0, j], 100 * cov["coverage_95_err"].values[0, j]
        b, sp = cov["bias_over_se"].values[0, j], cov["spread_over_se"].values[0, j]
        lines.append(f"  {label:6s} {q:40s} {c:5.1f} ± {e:3.1f} %   bias/SE {b:+.3f}   spread/SE {sp:.2f}")
    return lines


def main() -> None:
    """Run the set-ups named on the command line and print their tables."""
    args = sys.argv[1:]
    reps = int(args.pop(0))
    names = args or list(SETUPS)
    variants = [v for v in VARIANTS if v in names] or list(VARIANTS)
    names = [n for n in names if n in SETUPS]
    cfg = load_config()
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    cache: dict = {}
    real_source = chain.source

    def cached_source(settings, *rest, **kw):
        seeds = (settings.synthetic.seed, settings.render.seed if settings.render else None)
        if seeds not in cache:
            cache[seeds] = real_source(settings, *rest, **kw)
        return cache[seeds]

    quantities = tuple(q for q in STUDY_QUANTITIES if q != "eta2")
    for name in names:
        s = StudySettings.from_config(cfg, "calibration")
        s = replace(s, dataset=SETUPS[name](s.dataset), replicates=reps, batch_size=reps, truth_impacts=2000)
        cache.clear()
        t0 = time.perf_counter()
        truth = [population_truth(s, 0, balls, bats)]
        out = [f"{name}: {reps} replicates (truth {time.perf_counter() - t0:.0f} s)"]
        with (
            mock.patch.object(chain, "source", cached_source),
            mock.patch.object(replicates, "STUDY_QUANTITIES", quantities),
        ):
            for label in variants:
                form, term, within, robust, contact, kh, bat_sandwich = VARIANTS[label]
                t0 = time.perf_counter()
                with (
                    mock.patch.object(fitting, "E_Y_SANDWICH", form),
                    mock.patch.object(linefit, "SCATTER_TERM", term),
                    mock.patch.object(fitting, "WITHIN_BAT_SCATTER", within),
                    mock.patch.object(fitting, "POOLED_SANDWICH", robust),
                    mock.patch.object(fitting, "CONTACT_POPULATION_ERROR", contact),
                    mock.patch.object(linefit, "KNAPP_HARTUNG_FLOOR", kh),
                    mock.patch.object(fitting, "PER_BAT_SANDWICH", bat_sandwich),
                ):
                    rep = study_batch.run(s, 0, balls, bats)
                    truth_v = [population_truth(s, 0, balls, bats)] if term else truth
                out += [*table(coverage(rep, truth_v), label), f"  {label}: {time.perf_counter() - t0:.0f} s"]
        print("\n".join(out), flush=True)


if __name__ == "__main__":
    main()
