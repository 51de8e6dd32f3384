# ballbat: oblique ball-bat collisions, end to end (Kensrud, Nathan & Smith 2017).
# A table of contents: config, validation, one file of rules per stage, and the targets.
from snakemake.utils import min_version

min_version("9.0")


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
include: "workflow/rules/implications.smk"
include: "workflow/rules/plots.smk"  # last: draws what the others write


rule all:
    """Every dataset's paper comparison (and all that it needs)."""
    input:
        TARGETS,
    default_target: True
