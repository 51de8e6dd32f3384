"""The carry bands of a lab's own bat: do they cover the truth (issue 37, section 3; docs/flight.md).

Each replicate is a lab's test session of its own bat: the example hickory bat
(config/examples/hickory_bats.csv, lab convention) hit N times by baseballs with true e_x 0.455,
simulated in direct-noise mode with the default's noise and run through the chain
(:func:`ballbat.chain.run`). A calibration systematic is drawn as bench/league_season.py draws it:
the session's e_x moves by ``s * delta``, ``delta ~ N(0, 1)``, ``s = 0.012 e_x``, recorded as the
bat's ``e_x_syst``. The scenario (90 mph pitch, 70 mph swing, the paper's other settings; D = 0,
0.5, 1.0 in) is then run with the fitted e_x and its bands (:func:`ballbat.scenario_bands.scenario_with_bands`,
the workflow's and ``ballbat hit``'s code) and with the true e_x; a band covers when the true
quantity lies inside it.

Run: ``nice -n 10 PYTHONPATH=src .venv/bin/python bench/carry_bands.py [replicates] [impacts] [seed]``
(one process; 400 replicates of 30 impacts take about 4 minutes). Prints the coverage of the 68 %
and 95 % bands of carry (and of exit speed, launch angle, backspin) at each D, with Clopper-Pearson
95 % intervals.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from scipy import stats

from ballbat import chain, scenario_bands
from ballbat.pipeline.config import checked_block
from ballbat.properties import load_balls, load_bats
from ballbat.stages import implications as stage

ROOT = Path(__file__).resolve().parents[1]
TRUE_E_X = 0.455
REL_SYST = 0.012
SWEEP = {
    "pitch_mph": 90.0,
    "pitch_descent_deg": 6.0,
    "pitch_backspin_rpm": 2000.0,
    "bat_mph": 70.0,
    "attack_deg": 6.0,
    "D_in": {"start": 0.0, "stop": 1.0, "num": 3},
}


def fitted(seed: int, impacts: int, tables: tuple, rng: np.random.Generator) -> scenario_bands.DatasetEx:
    """One session of the hickory bat through the chain; its e_x moved by a drawn calibration error."""
    block = {"impacts": {"baseball": {"hickory": impacts}}, "e_x": {"baseball": {"hickory": TRUE_E_X}}}
    syn = checked_block({**block, "e_y": {"baseball": 0.45}, "seed": seed}, "synthetic")
    settings = chain.schema_settings({"synthetic": syn}, "session")
    fit = chain.run(settings, chain.source(settings, *tables), *tables).fit_ex
    sel = {"ball": "baseball", "bat": "hickory"}
    s = REL_SYST * TRUE_E_X
    value = float(fit["e_x"].sel(**sel)) + s * float(rng.standard_normal())
    return scenario_bands.DatasetEx(value, float(fit["e_x_err"].sel(**sel)), s, "bat", "session")


def rate(k: int, n: int) -> str:
    """k/n with its Clopper-Pearson 95 % interval."""
    lo = stats.beta.ppf(0.025, k, n - k + 1) if k else 0.0
    hi = stats.beta.ppf(0.975, k + 1, n - k) if k < n else 1.0
    return f"{k / n:.3f} [{lo:.3f}, {hi:.3f}]"


def main(n: int = 400, impacts: int = 30, seed0: int = 20261128) -> None:
    """Run ``n`` replicates and print the bands' coverage."""
    tables = (load_balls(ROOT / "config" / "balls.csv"), load_bats(ROOT / "config" / "examples" / "hickory_bats.csv"))
    imp = checked_block({"scenarios": {"s": {"ball": "baseball", "bat": "hickory", "sweep": SWEEP}}}, "implications")
    settings = stage.ImplicationsSettings(scenario=imp["scenarios"]["s"], air=imp["air"])
    truth = stage.run(settings, *tables, e_x=TRUE_E_X)
    rng = np.random.default_rng(seed0)
    hits = {(q, t): np.zeros(truth.sizes["case"], dtype=int) for q in scenario_bands.BANDED for t in ("68", "95")}
    t0 = time.process_time()
    for i in range(n):
        ds = scenario_bands.scenario_with_bands(settings, *tables, fitted(seed0 + i, impacts, tables, rng))
        for q, t in hits:
            inside = (ds[f"{q}_low{t}"].values <= truth[q].values) & (truth[q].values <= ds[f"{q}_high{t}"].values)
            hits[(q, t)] += inside
    print(
        f"{n} replicates of {impacts} impacts of the hickory bat (true e_x {TRUE_E_X}), "
        f"{time.process_time() - t0:.0f} s CPU"
    )
    D = truth["D"].values / 0.0254
    for q in scenario_bands.BANDED:
        for k, d in enumerate(D):
            print(
                f"{q:13} D = {d:.2f} in: 68 % band covers {rate(int(hits[(q, '68')][k]), n)}, "
                f"95 % band covers {rate(int(hits[(q, '95')][k]), n)}"
            )


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:4]))
