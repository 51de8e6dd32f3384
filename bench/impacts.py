"""Random true impacts for the benches (speeds, angle, spin and impact angle across the paper's ranges), and the
camera tracks' render block the track benches draw them with.
"""

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


#: The ``render`` block of the track benches (bench_tracks.py, bench_track_blocks.py): the default
#: config's cameras and rig, the schema's defaults for the rest.
RENDER_CFG = {
    "cameras": {
        "swing": {"fps": 3000, "m_per_px": 0.00074, "tee_px": [540, 480]},
        "spin": {"fps": 1000, "m_per_px": 0.00125, "tee_px": [600, 480], "pre_impact_frames": 5},
    },
    "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
    "seed": 1,
}
