# The report's front page (workflow/report/workflow.rst pulls these in): the run's headline
# numbers, written from the NetCDF files (ballbat.frontpage), as the figure captions are.


rule report_front:
    """Write the report's front page: what was run, e_x and eta^2 beside the paper's, warnings, provenance.

    It comes last (every other product of the run is its input), so the warnings of every job are in.
    """
    input:
        impacts=expand(f"{R}/{{dataset}}/reconstruct.nc", dataset=DATASETS),
        fit=expand(f"{R}/{{dataset}}/fit_ex.nc", dataset=DATASETS),
        stronge=expand(f"{R}/{{dataset}}/stronge.nc", dataset=DATASETS),
        fig5=expand(f"{R}/{{dataset}}/figures/fig5.png", dataset=DATASETS),
        scenarios=expand(f"{R}/implications/{{scenario}}.nc", scenario=SCENARIOS),
        league=[t for t in LEAGUE_TARGETS if t.endswith(".nc")],
        rest=final_targets(),
        code=code("report_front.py"),
    output:
        rst=f"{R}/report/front.rst",
    log:
        f"{R}/report/logs/front.log",
    conda:
        ENV
    params:
        kinds={d: dataset_kind(d) for d in DATASETS},
        scenarios=SCENARIOS,
    script:
        "../scripts/report_front.py"


rule report_front_studies:
    """Write the studies' lines of the report's front page: coverage range and a design's impacts per bat."""
    input:
        coverage=expand(f"{R}/studies/{{study}}/coverage.nc", study=STUDIES),
        design=[t for t in study_targets() if t.endswith("design.nc")],
        code=code("report_front.py"),
    output:
        rst=f"{R}/studies/front.rst",
    log:
        f"{R}/studies/logs/front.log",
    conda:
        ENV
    params:
        studies=STUDIES,
        designs={Path(t).parent.name: t for t in study_targets() if t.endswith("design.nc")},
    script:
        "../scripts/report_front.py"
