"""Rule fit_ex: adapter around ballbat.stages.fit_ex.run."""

from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.stages import fit_ex

with logged(snakemake.log[0], snakemake.rule) as log:
    settings = fit_ex.FitExSettings.from_params(dict(snakemake.params))
    ds = fit_ex.run(settings, read_dataset(snakemake.input.impacts))
    for line in fit_ex.not_fitted(ds):
        log.warning(line)
    write_job_output(
        ds,
        snakemake,
        "fit",
        f"Fits of e_x, Eq. ratio and Figs. 3-4 for dataset {snakemake.wildcards.dataset} (Sec. IV)",
    )
