"""Rule fit_stronge: adapter around ballbat.stages.stronge.run."""

from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.stages import stronge

with logged(snakemake.log[0], snakemake.rule) as log:
    ds = stronge.run(
        stronge.StrongeSettings.from_params(snakemake.params.stronge), read_dataset(snakemake.input.impacts)
    )
    for b in ds.ball.values:
        f = ds.sel(ball=b)
        log.info("%s: eta2 = %.3f +- %.3f (n = %d, reduced chi2 %.2f)", b, f.eta2, f.eta2_err, f.eta2_n, f.eta2_redchi)
    write_job_output(
        ds, snakemake, "stronge", f"Stronge contact model fitted to dataset {snakemake.wildcards.dataset} (Sec. V.A)"
    )
