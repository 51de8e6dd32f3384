"""Random true impacts for the benches: speeds, angle, spin and impact angle across the paper's ranges."""

import numpy as np

from ballbat.units import DEGREE, MPH, RPM


def random_impacts(n: int, seed: int = 0, omega_min_rpm: float = 0.0) -> dict[str, np.ndarray]:
    """Return ``n`` impacts' true v_bat, v_ball, theta, omega and psi (SI units) drawn from ``seed``."""
    rng = np.random.default_rng(seed)
    return {
        "v_bat": rng.uniform(63, 88, n) * MPH,
        "v_ball": rng.uniform(55, 100, n) * MPH,
        "theta": rng.uniform(0, 30, n) * DEGREE,
        "omega": rng.uniform(omega_min_rpm, 3500, n) * RPM,
        "psi": rng.uniform(0, 35, n) * DEGREE,
    }
