# ballbat: oblique ball-bat collisions, end to end (Kensrud, Nathan & Smith 2017).
# A table of contents: config, validation, one file of rules per stage, and the targets.
from snakemake.utils import min_version

from ballbat.pipeline.parsed import keep_parsed, save_parsed

min_version("9.0")
# The rule files' translation into Python, kept by their content (ballbat.pipeline.parsed; saved below).
keep_parsed(".snakemake/ballbat/parsed.json")


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/source.smk"
include: "workflow/rules/tracks.smk"
include: "workflow/rules/normalize.smk"
include: "workflow/rules/reconstruct.smk"
include: "workflow/rules/fit_ex.smk"
include: "workflow/rules/stronge.smk"
include: "workflow/rules/compare.smk"
include: "workflow/rules/league.smk"
include: "workflow/rules/implications.smk"
include: "workflow/rules/plots.smk"
include: "workflow/rules/workbook.smk"
include: "workflow/rules/studies.smk"
include: "workflow/rules/report.smk"


# The rules' code inputs and the rule files' translations as read this time, kept for the next start.
save_code_record()
save_parsed()


# Cheap jobs (drawing, tabulating) run where Snakemake runs, never as cluster jobs.
localrules:
    all,
    compare,
    league,
    plot_league,
    league_workbook,
    comparison_html,
    implications_compare,
    workbook,
    implications_workbook,
    plot_fig3,
    plot_fig4,
    plot_fig5,
    plot_fig6,
    plot_fig9,
    plot_fig10,
    plot_fig11,
    plot_launch,
    tracks_qa,
    clips_quality,
    studies,
    study_design,
    plot_study_coverage,
    plot_study_design,
    report_front,
    report_front_studies,


# When a real run starts: no file the workflow did not write is replaced; dead jobs' temporaries go.
onstart:
    start_run(workflow.dag)


# Every warning of the run's jobs, printed at its end, success or not; then the run's Provenance Run
# Crate ({R}/ro-crate-metadata.json; common.smk: write_crate), marked failed after a failure.
onsuccess:
    print_warnings(R, DATASETS, SCENARIOS)
    write_crate()


onerror:
    print_warnings(R, DATASETS, SCENARIOS)
    write_crate(failed=True)


# All products of every dataset and scenario, intermediate files included (common.smk: final_targets).
rule all:
    default_target: True
    input:
        final_targets(),
        LEAGUE_TARGETS,
        f"{R}/report/front.rst",
