"""The study of config/examples/property_study.yaml in one process: coverage of e_x with drawn bat properties.

Each replicate draws its true hickory bat from the lab sheet's stated uncertainties
(config/examples/property_study_bats.csv: weight 0.1 oz, balance point 0.1 in, MOI 3 %, impact
point 0.25 in), simulates 150 baseball and 150 softball impacts on it (direct measurement
noise), and analyses them with the sheet's values and their property systematics
(docs/studies.md, "Studies that draw the bat's properties"). Prints, per quantity, the
coverage of the statistical and of the combined (stat and syst in quadrature) 68 % and 95 %
intervals, judged against each replicate's own truth (the estimator on its noise-free values
with its true bat), and the mean statistical and systematic errors.

    PYTHONPATH=src .venv/bin/python bench/property_study.py [--replicates N] [--batches B]

Same numbers as ``snakemake -c2 --configfile config/examples/property_study.yaml
results/studies/properties/coverage.csv`` (its coverage judges the pooled truth of the design
instead; e_x's truth is the bat's, which drawing its properties does not change).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from ballbat.config_checks import validate_config  # noqa: E402
from ballbat.properties import load_balls, load_bats  # noqa: E402
from ballbat.studies import batch as study_batch  # noqa: E402
from ballbat.studies.coverage import combine, coverage  # noqa: E402
from ballbat.studies.settings import StudySettings  # noqa: E402

EXAMPLE = ROOT / "config" / "examples" / "property_study.yaml"
COLUMNS = (
    "n_replicates",
    "coverage_68",
    "coverage_95",
    "coverage_68_combined",
    "coverage_95_combined",
    "coverage_95_combined_err",
    "mean_uncertainty",
    "mean_systematic",
    "spread",
)


def settings(replicates: int | None) -> StudySettings:
    """The study's settings: the example merged over the default config, as ``--configfile`` merges it."""
    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    over = yaml.safe_load(EXAMPLE.read_text())
    base["datasets"].update(over["datasets"])
    base["studies"].update(over["studies"])
    if replicates:
        base["studies"]["properties"]["replicates"] = replicates
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    return StudySettings.from_config(validate_config(base, schema), "properties")


def main() -> None:
    """Run the study and print its coverage table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--replicates", type=int, default=None, help="replicates (default: the example's)")
    args = ap.parse_args()
    st = settings(args.replicates)
    balls = load_balls(ROOT / "config" / "balls.csv")
    bats = load_bats(ROOT / over_bats())
    start = time.process_time()
    batches = [study_batch.run(st, b, balls, bats) for b in range(st.n_batches)]
    cpu = time.process_time() - start
    cov = coverage(combine(batches))
    print(f"{st.replicates} replicates, seed {st.seed}, {cpu / 60:.1f} CPU minutes ({cpu / st.replicates:.2f} s each)")
    print(f"{'quantity':<34}" + "".join(f" {c.replace('coverage_', 'cov_'):>15}" for c in COLUMNS))
    for j, label in enumerate(cov["quantity"].values.astype(str)):
        if not label.startswith(("e_x", "eta2")):
            continue
        cells = [cov[c].values[0, j] for c in COLUMNS]
        print(f"{label:<34}" + "".join(f" {c:15.4f}" if c == c else f" {'':>15}" for c in cells))


def over_bats() -> str:
    """The example dataset's bat table (its path as the config names it)."""
    over = yaml.safe_load(EXAMPLE.read_text())
    return over["datasets"]["hickory_study"]["bats"]


if __name__ == "__main__":
    main()
