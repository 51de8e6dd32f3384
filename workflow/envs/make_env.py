"""Write workflow/envs/ballbat.yaml (every rule's `conda:`) from requirements.lock.

Run by `make lock`; tests/test_lint.py checks that the two agree.
"""

from pathlib import Path

HERE = Path(__file__).resolve().parent
HEADER = """\
# Software environment of every rule (`conda:` in workflow/rules/*.smk), for `snakemake --sdm conda`.
# The default `make run` uses the pinned virtual environment instead; both install exactly
# requirements.lock (tests/test_lint.py checks that this list and the lock file agree).
# Written by workflow/envs/make_env.py (`make lock`); do not edit by hand.
name: ballbat
channels:
  - conda-forge
  - nodefaults
dependencies:
  - python=3.11
  - pip
  - pip:
"""


def main() -> None:
    """Write the conda file from the lock file."""
    pins = [line.strip() for line in (HERE.parents[1] / "requirements.lock").read_text().splitlines() if line.strip()]
    body = HEADER + "".join(f"      - {p}\n" for p in pins) + "      - -e ../..  # ballbat itself, from this checkout\n"
    (HERE / "ballbat.yaml").write_text(body)


if __name__ == "__main__":
    main()
