# The bats league table (docs/league.md): every bat's e_x over the run's datasets, when there is
# anything to compare (more than one dataset, or more than one bat of a ball in a dataset).


def _bats_per_ball(name):
    """The most bats of one ball in dataset ``name`` as the config tells it (None: the config does not say)."""
    block = config["datasets"][name]
    if "synthetic" in block:
        return max(sum(1 for n in per.values() if n) for per in block["synthetic"]["impacts"].values())
    return None  # a measured file: read only when the job runs


def league_wanted():
    """Whether a run makes the league table: more than one dataset, or a dataset with several bats of a ball."""
    counts = [_bats_per_ball(d) for d in DATASETS]
    return len(DATASETS) > 1 or any(c is None or c > 1 for c in counts)


LEAGUE_TARGETS = (
    ["results/league.nc", "results/league.csv", "results/league.xlsx", "results/figures/league_forest.png"]
    if league_wanted()
    else []
)


rule league:
    """The league table: e_x per bat and test session, pairwise tests (Holm), consistency, TOST, forest plot."""
    input:
        fits=expand("results/{dataset}/fit_ex.nc", dataset=DATASETS),
        code=code("league.py"),
    output:
        nc="results/league.nc",
        csv="results/league.csv",
        prov="results/league.provenance.json",
        xlsx="results/league.xlsx",
        forest=report(
            "results/figures/league_forest.png",
            caption="../report/league.rst",
            category="League table",
            labels={"figure": "forest plot"},
        ),
    params:
        league=config["league"],
        sessions={d: config["datasets"][d].get("session") for d in DATASETS},
    log:
        "results/logs/league.log",
    conda:
        ENV
    script:
        "../scripts/league.py"
