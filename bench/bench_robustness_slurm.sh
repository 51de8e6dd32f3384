#!/usr/bin/env bash
# The robustness study's wall time through a real SLURM (the workflow's slurm profile) against the
# same study run locally with -c2 (issue 22). Brings the single-node test cluster up and down
# (tests/slurm/cluster.sh; root needed) and uses .venv-slurm (make test-slurm builds it).
#
# Usage: bench/bench_robustness_slurm.sh [CONFIGFILE]
#   CONFIGFILE: a --configfile for the study (default bench/robustness_slurm.yaml, 4 grid points).
# Prints both wall times, the jobs submitted and the wall time SLURM adds per job; the full
# study's time through SLURM is about its local time plus that times its 136 jobs.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BIN="${BIN:-$ROOT/.venv-slurm/bin}"
HERE="$ROOT/tests/slurm"
CONFIG=$(realpath "${1:-$ROOT/bench/robustness_slurm.yaml}")
TARGET=results/studies/robustness/coverage.csv

# shellcheck source=tests/slurm/lib.sh
. "$HERE/lib.sh"
cluster_and_two_checkouts ballbat-robustness
export PATH="$BIN:$PATH"
start=$(date +%s)
(cd "$WORK/local" && snakemake "$TARGET" -c2 --quiet all --configfile "$CONFIG") >"$WORK/local.log" 2>&1 || {
    tail -n 40 "$WORK/local.log"
    exit 1
}
local_s=$(($(date +%s) - start))
start=$(date +%s)
(cd "$WORK/slurm" && snakemake "$TARGET" --workflow-profile workflow/profiles/slurm --configfile "$CONFIG") \
    >"$WORK/slurm.log" 2>&1 || {
    tail -n 60 "$WORK/slurm.log"
    exit 1
}
slurm_s=$(($(date +%s) - start))
jobs=$(grep -c "SLURM jobid" "$WORK/slurm.log" || true)
echo "robustness study ($(basename "$CONFIG")): local -c2 ${local_s} s, through SLURM ${slurm_s} s, ${jobs} cluster jobs"
if [ "$jobs" -gt 0 ]; then
    echo "SLURM adds $(((slurm_s - local_s) / jobs)) s of wall time per job (submission, the job step's start, squeue polling)"
fi
cmp "$WORK/local/$TARGET" "$WORK/slurm/$TARGET" && echo "coverage.csv byte-identical"
rm -rf "$WORK"
