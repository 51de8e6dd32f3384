"""Rule normalize: adapter around ballbat.analysis.normalize."""

from ballbat.analysis import normalize
from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged

with logged(snakemake.log[0], snakemake.rule):
    ds = normalize(read_dataset(snakemake.input.impacts), v_ref_mph=snakemake.params.v_ref_mph)
    write_job_output(
        ds,
        snakemake,
        "impacts",
        (
            f"Impacts of dataset {snakemake.wildcards.dataset}, "
            f"spin and exit speed normalised to {snakemake.params.v_ref_mph:g} mph"
        ),
    )
