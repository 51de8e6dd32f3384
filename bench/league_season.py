"""A synthetic season of the bats league table (issue 37): the error rates of its tests.

Are the bats that truly differ found, and the pairs that truly agree not, at the stated error rates?

Each season is three test sessions of synthetic impacts (direct-noise mode, the default's noise) of
bats with known e_x, run through the chain (:func:`ballbat.chain.run`) and the league
(:func:`ballbat.league.league`):

=========  ===============================================  ===========================================
session    baseball bats (impacts)                          softball bats (impacts)
=========  ===============================================  ===========================================
s1         wood 20, metal_rough 20, metal_smooth 20         wood 13, metal_rough 13, softball_composite 12
s2         wood 20, metal_smooth 20                         metal_rough 13, metal_smooth 13
s3         metal_rough 20, metal_smooth 20                  wood 13, metal_smooth 12, softball_composite 12
=========  ===============================================  ===========================================

True e_x: baseball wood 0.450, metal_rough 0.450, metal_smooth 0.480; softball wood 0.200,
metal_rough 0.200, metal_smooth 0.200, softball_composite 0.230. So 4 pairs truly agree (baseball
wood/metal_rough; softball wood/metal_rough, wood/metal_smooth, metal_rough/metal_smooth) and 5 differ
by 0.03. A session's calibration systematic is drawn as the default's swing pixel scale does it: each
session draws one delta ~ N(0, 1) and every e_x of the session moves by ``s * delta`` with
``s = 0.012 e_x`` (about the default's 0.005 per bat), written as that session's
``e_x_syst_by_source`` (swing_m_per_px) for the league to use. The sessions' covariances are therefore
the league's model; the statistical errors are the chain's own.

Measured per season: any truly-agreeing pair declared different (family-wise error, Holm at 0.05),
each truly-differing pair found (power), each bat's consistency test rejecting at 0.05 (bats in
2-3 sessions, all consistent by construction), and the TOST of metal_rough against wood (baseball;
truly equal, margin 0.02: power) and of metal_smooth (0.03 apart: equivalence must not be claimed).

Run: ``nice -n 10 PYTHONPATH=src .venv/bin/python bench/league_season.py [seasons] [seed]``
(one process; 300 seasons take about 4 minutes). Prints the rates with Clopper-Pearson 95 % intervals.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from scipy import stats

from ballbat import chain, league
from ballbat.pipeline.config import checked_block
from ballbat.properties import load_balls, load_bats

ROOT = Path(__file__).resolve().parents[1]
TRUE = {
    "baseball": {"wood": 0.450, "metal_rough": 0.450, "metal_smooth": 0.480},
    "softball": {"wood": 0.200, "metal_rough": 0.200, "metal_smooth": 0.200, "softball_composite": 0.230},
}
SESSIONS = {
    "s1": {
        "baseball": {"wood": 20, "metal_rough": 20, "metal_smooth": 20},
        "softball": {"wood": 13, "metal_rough": 13, "softball_composite": 12},
    },
    "s2": {"baseball": {"wood": 20, "metal_smooth": 20}, "softball": {"metal_rough": 13, "metal_smooth": 13}},
    "s3": {
        "baseball": {"metal_rough": 20, "metal_smooth": 20},
        "softball": {"wood": 13, "metal_smooth": 12, "softball_composite": 12},
    },
}
REL_SYST = 0.012


def session_fit(name: str, impacts: dict, seed: int, delta: float, tables: tuple) -> league.Session:
    """One session through the chain, its e_x moved by its calibration draw and the systematic recorded."""
    e_x = {ball: {bat: TRUE[ball][bat] for bat in per} for ball, per in impacts.items()}
    syn = checked_block({"impacts": impacts, "e_x": e_x, "e_y": {"baseball": 0.45, "softball": 0.32}}, "synthetic")
    settings = chain.schema_settings({"synthetic": {**syn, "seed": seed}}, name)
    fit = chain.run(settings, chain.source(settings, *tables), *tables).fit_ex
    truth = np.array([[TRUE[b].get(t, np.nan) for t in fit["bat"].values] for b in fit["ball"].values])
    s = np.where(fit["e_x_n"].values > 0, REL_SYST * truth, 0.0)
    fit["e_x"] = fit["e_x"] + s * delta
    per = np.zeros((len(league.SHARING), *s.shape))
    per[0] = s
    fit = fit.assign_coords(systematic=list(league.SHARING))
    fit["e_x_syst_by_source"] = (("systematic", "ball", "bat"), per)
    return league.Session(f"season/{name}", "season", name, fit)


def season(seed: int, tables: tuple, settings: league.LeagueSettings) -> dict:
    """One season's outcomes (booleans and counts)."""
    rng = np.random.default_rng(seed)
    sessions = [
        session_fit(name, imp, seed * 10 + k, float(rng.standard_normal()), tables)
        for k, (name, imp) in enumerate(SESSIONS.items())
    ]
    ds = league.league(sessions, settings)
    out = {"false_pair": False, "found": {}, "consistency": []}
    for i in range(ds.sizes["pair"]):
        ball, a, b = (str(ds[k].values[i]) for k in ("pair_ball", "pair_bat_a", "pair_bat_b"))
        differs = bool(ds["pair_differs"].values[i])
        if TRUE[ball][a] == TRUE[ball][b]:
            out["false_pair"] |= differs
        else:
            out["found"][(ball, a, b)] = differs
    for i in range(ds.sizes["row"]):
        if ds["consistency_dof"].values[i] > 0:
            out["consistency"].append(bool(ds["consistency_p"].values[i] < settings.alpha))
    base = {str(ds["bat"].values[i]): i for i in range(ds.sizes["row"]) if ds["ball"].values[i] == "baseball"}
    out["tost_equal"] = bool(ds["tost_equivalent"].values[base["metal_rough"]] == 1)
    out["tost_apart"] = bool(ds["tost_equivalent"].values[base["metal_smooth"]] == 1)
    return out


def rate(k: int, n: int) -> str:
    """k/n with its Clopper-Pearson 95 % interval."""
    lo = stats.beta.ppf(0.025, k, n - k + 1) if k else 0.0
    hi = stats.beta.ppf(0.975, k + 1, n - k) if k < n else 1.0
    return f"{k}/{n} = {k / n:.3f} [{lo:.3f}, {hi:.3f}]"


def main(n: int = 300, seed0: int = 20261127) -> None:
    """Run ``n`` seasons and print the error rates and the power."""
    tables = (load_balls(ROOT / "config" / "balls.csv"), load_bats(ROOT / "config" / "bats.csv"))
    settings = league.LeagueSettings.from_config({"league": {"reference_bat": "wood", "margin": 0.02}})
    t0 = time.process_time()
    runs = [season(seed0 + i, tables, settings) for i in range(n)]
    print(f"{n} seasons of 3 test sessions, {time.process_time() - t0:.0f} s CPU")
    print(
        f"family-wise error (any of 4 truly-agreeing pairs declared different, Holm 0.05): "
        f"{rate(sum(r['false_pair'] for r in runs), n)}"
    )
    for key in runs[0]["found"]:
        print(
            f"power, {key[0]} {key[1]} vs {key[2]} (true difference 0.030): "
            f"{rate(sum(r['found'][key] for r in runs), n)}"
        )
    allfound = sum(all(r["found"].values()) for r in runs)
    print(f"every truly-differing pair found: {rate(allfound, n)}")
    cons = [c for r in runs for c in r["consistency"]]
    print(f"consistency test rejecting a consistent bat at 0.05: {rate(sum(cons), len(cons))}")
    print(
        f"TOST, baseball metal_rough vs wood (equal; margin 0.02) shown equivalent: "
        f"{rate(sum(r['tost_equal'] for r in runs), n)}"
    )
    print(
        f"TOST, baseball metal_smooth vs wood (0.030 apart) wrongly shown equivalent: "
        f"{rate(sum(r['tost_apart'] for r in runs), n)}"
    )


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3]))
