"""Rule fit_ex: adapter around ballbat.fitting.fit_dataset."""

from ballbat.fitting import fit_dataset, not_fitted
from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged

with logged(snakemake.log[0], snakemake.rule) as log:
    ds = fit_dataset(read_dataset(snakemake.input.impacts), mu_k_example=snakemake.params.mu_k_example)
    for line in not_fitted(ds):
        log.warning(line)
    write_job_output(
        ds,
        snakemake,
        "fit",
        f"Fits of e_x, Eq. ratio and Figs. 3-4 for dataset {snakemake.wildcards.dataset} (Sec. IV)",
    )
