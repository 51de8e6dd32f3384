#!/usr/bin/env bash
# make test-slurm: the default workflow and a small replicate study (tests/slurm/study.yaml)
# through a real SLURM (single node, this machine) and locally; every result file must be
# byte-identical. Sets the cluster up and tears it down.
set -euo pipefail
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
BIN="${BIN:-$ROOT/.venv-slurm/bin}"  # an environment with the executor plugin (make test-slurm)
HERE="$ROOT/tests/slurm"

# shellcheck source=tests/slurm/lib.sh
. "$HERE/lib.sh"
cluster_and_two_checkouts ballbat-slurm

export PATH="$BIN:$PATH"
TARGETS=(all studies)
CONFIG=(--configfile "$HERE/study.yaml")  # last: --configfile takes every word after it
(cd "$WORK/local" && snakemake "${TARGETS[@]}" -c2 --quiet "${CONFIG[@]}") >"$WORK/local.log" 2>&1 || {
    tail -n 40 "$WORK/local.log"
    exit 1
}
start=$(date +%s)
(cd "$WORK/slurm" && snakemake "${TARGETS[@]}" --workflow-profile workflow/profiles/slurm "${CONFIG[@]}") >"$WORK/slurm.log" 2>&1 || {
    tail -n 60 "$WORK/slurm.log"
    exit 1
}
echo "slurm: default workflow and a small study in $(($(date +%s) - start)) s through the executor"
submitted=$(grep -c "SLURM jobid" "$WORK/slurm.log" || true)
echo "slurm: ${submitted} cluster jobs submitted (the rest ran on the submitting host: localrules)"
[ "$submitted" -gt 0 ] || { echo "slurm: nothing went through the cluster" >&2; exit 1; }

"$BIN/python" - "$WORK/local/results" "$WORK/slurm/results" <<'EOF'
import hashlib, pathlib, sys
local, slurm = map(pathlib.Path, sys.argv[1:3])
kinds = ("*.nc", "*.csv", "*.md", "*.xlsx", "*.png")
files = sorted(p.relative_to(local) for k in kinds for p in local.rglob(k))
digest = lambda p: hashlib.sha256(p.read_bytes()).hexdigest()
differ = [str(f) for f in files if not (slurm / f).is_file() or digest(local / f) != digest(slurm / f)]
studies = sum(1 for f in files if f.parts[0] == "studies")
print(f"slurm: {len(files) - len(differ)} of {len(files)} result files byte-identical to the local run "
      f"({studies} of them the study's)")
if studies < 10:
    print("slurm: the study's results are missing")
    sys.exit(1)
if differ:
    print("differ:", *differ, sep="\n  ")
    sys.exit(1)
EOF
rm -rf "$WORK"
