"""Time ballbat.flight.fly: 1e4 trajectories with the accurate integrator, 1e3 with the
calculator's fixed-step scheme.

Run: ``.venv/bin/python bench/bench_flight.py``. Launch conditions are drawn uniformly from
60-115 mph, -10-70 deg launch, +-45 deg spray, -1000-6000 rpm backspin and +-1500 rpm
sidespin (fixed seed). Prints the best of three wall-clock times.
"""

from __future__ import annotations

import time

import numpy as np

from ballbat.flight import fly
from ballbat.units import DEGREE, FOOT, MPH, RPM


def launch_conditions(n: int, seed: int = 2017) -> tuple[np.ndarray, ...]:
    """Draw ``n`` launch conditions (fixed seed)."""
    rng = np.random.default_rng(seed)
    return (
        rng.uniform(60, 115, n) * MPH,
        rng.uniform(-10, 70, n) * DEGREE,
        rng.uniform(-45, 45, n) * DEGREE,
        rng.uniform(-1000, 6000, n) * RPM,
        rng.uniform(-1500, 1500, n) * RPM,
    )


def best_time(n: int, method: str, repeat: int = 3) -> tuple[float, np.ndarray]:
    """Return the best of ``repeat`` wall-clock times of ``n`` flights, and the carries."""
    args = launch_conditions(n)
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = fly(*args, method=method)
        best = min(best, time.perf_counter() - t0)
    return best, res.carry


def main() -> None:
    """Print the timings."""
    fly(*launch_conditions(10))  # warm-up (imports, caches)
    for n, method in ((10_000, "accurate"), (1_000, "calculator")):
        dt, carry = best_time(n, method)
        print(
            f"{method:>10}: {n:6d} trajectories in {dt:6.3f} s "
            f"({1e6 * dt / n:6.1f} us each; median carry {np.median(carry) / FOOT:5.1f} ft)"
        )


if __name__ == "__main__":
    main()
