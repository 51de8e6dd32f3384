"""Per-impact pulls of the reduced quantities at one point of the robustness grid.

Renders and reduces replicate experiments as a replicate study does
(:func:`ballbat.studies.replicates.replicate_source`) and prints, per ball and quantity, the mean and spread of
(value − truth) / stated error over every impact the reduction keeps. A mean away from 0 is a
bias of every impact. It becomes about mean * sqrt(n) standard errors on anything fitted to n
impacts (docs/studies.md, "Where softballs' implied e_y goes wrong").

Usage: ``.venv/bin/python bench/bench_pulls.py PX IMPACTS_PER_BAT CONTACT_MS [REPLICATES] [--draw]``
(``--draw``: the calibration drawn as the robustness study draws it).
"""

from __future__ import annotations

import argparse

import numpy as np

from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats
from ballbat.studies.replicates import replicate_seeds, replicate_source
from ballbat.studies.settings import StudySettings
from ballbat.studies.sweeps import point_dataset

QUANTITIES = ("v_bat", "v_ball", "theta", "omega")


def pulls(px: float, per_bat: int, contact_ms: float, replicates: int, draw: bool) -> dict:
    """Return {(ball, quantity): pulls of every kept impact over the replicates}."""
    cfg = load_config("config/config.yaml")
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    block = cfg["studies"]["robustness"]
    block["sweep"] = {"grid": {"pixel_noise_px": [px], "impacts_per_bat": [per_bat], "contact_ms": [contact_ms]}}
    block["draw_calibration"] = draw
    s = StudySettings.from_config(cfg, "robustness")
    dataset = point_dataset(s.dataset, s.parameter, s.values[0])
    out: dict = {}
    for rep in range(replicates):
        src = replicate_source(dataset, replicate_seeds(s.seed, rep), balls, bats, check=False)
        kept = src["ingest_flag"].values == 0
        ball = src["ball"].values.astype(str)
        for b in np.unique(ball):
            m = kept & (ball == b)
            for q in QUANTITIES:
                z = (src[q].values[m] - src[f"truth_{q}"].values[m]) / src[f"{q}_err"].values[m]
                out.setdefault((b, q), []).append(z)
    return {k: np.concatenate(v) for k, v in out.items()}


def main() -> None:
    """Print the pulls."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("px", type=float)
    ap.add_argument("impacts_per_bat", type=int)
    ap.add_argument("contact_ms", type=float)
    ap.add_argument("replicates", type=int, nargs="?", default=8)
    ap.add_argument("--draw", action="store_true")
    a = ap.parse_args()
    for (ball, q), z in sorted(pulls(a.px, a.impacts_per_bat, a.contact_ms, a.replicates, a.draw).items()):
        err = z.std() / np.sqrt(z.size)
        print(f"{ball:9s} {q:7s} impacts {z.size:5d}  mean pull {z.mean():+.3f} ± {err:.3f}  sd {z.std():.3f}")


if __name__ == "__main__":
    main()
