"""Benchmark of Stronge's contact model solver and of the eta^2 fit.

Run: ``.venv/bin/python bench/bench_stronge.py``. Prints

* impacts/s of :func:`ballbat.stronge.model.stronge_ex` for 1e6 impacts drawn from realistic
  ranges (psi 0-45 deg, eta2 4-8, e_y 0.4-0.6, mu 0.2-0.8, (r_x, r_y) of the Table I x II
  ball-bat pairs), and for a mix that needs the general phase machine (eta2 2-3.5);
* the reference solver's (solve_ivp) time per impact and the speed ratio;
* the time of :func:`ballbat.stronge.fit.fit_eta2` for one ball (58 impacts), with and
  without a free mu, lmfit's import time excluded (and printed separately).

Targets (task brief): >= 1e6 impacts/s, >= 1000x the reference, < 1 s per fit.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ballbat.properties import load_balls, load_bats, recoil_factors
from ballbat.stronge.model import ContactParams, stronge_ex, stronge_solve
from ballbat.stronge.reference import stronge_reference

ROOT = Path(__file__).resolve().parents[1]
DEG = np.pi / 180


def best_of(fn, repeat=3):
    """Return the best of ``repeat`` wall-clock times of ``fn()``."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    """Print the timings."""
    balls = load_balls(ROOT / "config" / "balls.csv")
    bats = load_bats(ROOT / "config" / "bats.csv")
    pairs = np.array([recoil_factors(b, t) for b in balls.values() for t in bats.values()])
    rng = np.random.default_rng(2017)
    n = 1_000_000
    k = rng.integers(0, len(pairs), n)
    psi = rng.uniform(0, 45, n) * DEG
    eta2 = rng.uniform(4, 8, n)
    e_y = rng.uniform(0.4, 0.6, n)
    mu = rng.uniform(0.2, 0.8, n)
    r_x, r_y = pairs[k, 0], pairs[k, 1]

    stronge_ex(psi[:1000], ContactParams(eta2[:1000], e_y[:1000], mu[:1000], r_x[:1000], r_y[:1000]))  # warm-up
    t_fast = best_of(lambda: stronge_ex(psi, ContactParams(eta2, e_y, mu, r_x, r_y)))
    print(f"stronge_ex, 1e6 realistic impacts: {t_fast:.3f} s -> {n / t_fast:,.0f} impacts/s")

    m = 100_000
    eta2_g = rng.uniform(2, 3.5, m)
    t_gen = best_of(lambda: stronge_ex(psi[:m], ContactParams(eta2_g, e_y[:m], mu[:m], r_x[:m], r_y[:m])), repeat=2)
    print(f"stronge_ex, 1e5 impacts with eta2 2-3.5 (general phase machine): {m / t_gen:,.0f} impacts/s")
    t_solve = best_of(
        lambda: stronge_solve(psi[:m], ContactParams(eta2[:m], e_y[:m], mu[:m], r_x[:m], r_y[:m])), repeat=2
    )
    print(f"stronge_solve (regimes, event times), 1e5 realistic impacts: {m / t_solve:,.0f} impacts/s")

    nr = 100
    sl = slice(0, nr)
    t0 = time.perf_counter()
    ref = stronge_reference(psi[sl], ContactParams(eta2[sl], e_y[sl], mu[sl], r_x[sl], r_y[sl]))
    t_ref = (time.perf_counter() - t0) / nr
    err = np.max(np.abs(ref["e_x"] - stronge_ex(psi[sl], ContactParams(eta2[sl], e_y[sl], mu[sl], r_x[sl], r_y[sl]))))
    per_fast = t_fast / n
    print(f"stronge_reference (solve_ivp DOP853, rtol 1e-12): {t_ref * 1e3:.2f} ms/impact")
    print(f"speed ratio reference/stronge_ex per impact: {t_ref / per_fast:,.0f}x (max |diff e_x| = {err:.1e})")

    t0 = time.perf_counter()
    import lmfit  # noqa: F401

    t_imp = time.perf_counter() - t0
    from ballbat.stronge.fit import fit_eta2

    ball = balls["baseball"]
    rr = np.array([recoil_factors(ball, bats[b]) for b in ("wood", "metal_rough", "metal_smooth")])
    kk = rng.integers(0, 3, 58)
    fx, fy = rr[kk, 0], rr[kk, 1]
    fpsi = rng.uniform(0, ball.psi_max, 58)
    x = np.tan(fpsi) / (1 + fx)
    y = (1 + stronge_ex(fpsi, ContactParams(4.75, 0.5, 0.5, fx, fy))) * x + rng.normal(0, 0.01, 58)
    print(f"lmfit import: {t_imp:.2f} s (once per process, not counted below)")
    for label, kw in (("eta2 only", {}), ("eta2 + mu", {"vary_mu": True}), ("eta2 + e_y", {"vary_e_y": True})):
        t = best_of(lambda kw=kw: fit_eta2(fpsi, x, y, fx, fy, **kw))
        f = fit_eta2(fpsi, x, y, fx, fy, **kw)
        print(
            f"fit_eta2 ({label}, 58 impacts, incl. profile interval): {t * 1e3:.0f} ms;"
            f" eta2 = {f.eta2:.3f} +- {f.eta2_err:.3f}, 95 % [{f.eta2_ci_low:.3f}, {f.eta2_ci_high:.3f}]"
        )


if __name__ == "__main__":
    main()
