# The bats league table (docs/league.md): every bat's e_x over the run's datasets, when there is
# anything to compare (more than one dataset, or more than one bat of a ball in a dataset).
LEAGUE_TARGETS = INPUTS.league_targets()


rule league:
    """The league table: e_x per bat and test session, pairwise tests (Holm), consistency, TOST."""
    input:
        fits=expand(f"{R}/{{dataset}}/fit_ex.nc", dataset=DATASETS),
        code=code("league.py"),
    output:
        nc=f"{R}/league.nc",
        csv=f"{R}/league.csv",
        prov=f"{R}/league.provenance.json",
    log:
        f"{R}/logs/league.log",
    conda:
        ENV
    params:
        league=config["league"],
        sessions={d: config["datasets"][d].get("session") for d in DATASETS},
    script:
        "../scripts/league.py"


rule plot_league:
    """The league table's forest plot."""
    input:
        league=rules.league.output.nc,
        code=code("plot_league.py"),
    output:
        png=report(
            f"{R}/figures/league_forest.png",
            caption="../report/league.rst",
            category="League table",
            labels={"figure": "forest plot"},
        ),
    log:
        f"{R}/logs/plot_league.log",
    conda:
        ENV
    script:
        "../scripts/plot_league.py"


rule league_workbook:
    """The league table as a spreadsheet: the table, the pairs, the sessions' entries, the provenance."""
    input:
        league=rules.league.output.nc,
        code=code("league_workbook.py"),
    output:
        xlsx=f"{R}/league.xlsx",
    log:
        f"{R}/logs/league_workbook.log",
    conda:
        ENV
    script:
        "../scripts/league_workbook.py"
