"""Rule normalize: adapter around ballbat.stages.normalize.run."""

from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.stages import normalize

with logged(snakemake.log[0], snakemake.rule):
    settings = normalize.NormalizeSettings.from_params(dict(snakemake.params))
    ds = normalize.run(settings, read_dataset(snakemake.input.impacts))
    write_job_output(
        ds,
        snakemake,
        "impacts",
        (
            f"Impacts of dataset {snakemake.wildcards.dataset}, "
            f"spin and exit speed normalised to {settings.v_ref_mph:g} mph"
        ),
    )
