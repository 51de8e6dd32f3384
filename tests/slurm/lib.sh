# Sourced by tests/slurm/run.sh and bench/bench_robustness_slurm.sh, which run the workflow locally
# and through SLURM side by side. Needs ROOT (the checkout) and HERE (tests/slurm).
#   cluster_and_two_checkouts NAME   bring the test cluster up (down again on exit) and copy the
#                                    workflow to $WORK/local and $WORK/slurm ($WORK: /tmp/NAME.XXXXXX)
cluster_and_two_checkouts() {
    trap '"$HERE/cluster.sh" down' EXIT INT TERM
    "$HERE/cluster.sh" up
    WORK=$(mktemp -d "/tmp/$1.XXXXXX")
    local side
    for side in local slurm; do
        mkdir -p "$WORK/$side"
        (cd "$ROOT" && cp -r Snakefile workflow config README.md "$WORK/$side/")
    done
}
