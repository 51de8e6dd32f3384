"""Rule fit_ex: adapter around ballbat.fitting.fit_dataset."""

import numpy as np

from ballbat.fitting import FitStatus, fit_dataset
from ballbat.pipeline.ncio import read_dataset, write_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import logged

with logged(snakemake.log[0], snakemake.rule) as log:
    ds = fit_dataset(read_dataset(snakemake.input.impacts), mu_k_example=snakemake.params.mu_k_example)
    for name in ("e_x", "e_x_pooled"):
        for where, status in ds[f"{name}_status"].to_series().items():
            if FitStatus(status) not in (FitStatus.OK, FitStatus.NO_IMPACTS):
                n = int(ds[f"{name}_n"].sel(dict(zip(ds[name].dims, np.atleast_1d(where), strict=True))))
                log.warning("%s %s: not fitted: %s (%d usable impacts)", name, where, FitStatus(status).name, n)
    write_dataset(
        ds,
        snakemake.output.fit,
        title=f"Fits of e_x, Eq. ratio and Figs. 3-4 for dataset {snakemake.wildcards.dataset} (Sec. IV)",
        rule=snakemake.rule,
        inputs=data_inputs(snakemake.input),
        config=dict(snakemake.params),
    )
