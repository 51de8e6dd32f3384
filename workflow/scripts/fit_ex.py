"""Rule fit_ex: adapter around ballbat.fitting.fit_dataset."""

from ballbat.fitting import fit_dataset
from ballbat.pipeline.ncio import read_dataset, write_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import logged
from ballbat.units import MPH

with logged(snakemake.log[0], snakemake.rule) as log:
    ds = fit_dataset(
        read_dataset(snakemake.input.impacts),
        v_ref=snakemake.params.v_ref_mph * MPH,
        mu_k_example=snakemake.params.mu_k_example,
    )
    for name in ("e_x", "e_x_pooled"):
        for where, note in ds[f"{name}_note"].to_series().items():
            if note not in ("ok", "no impacts"):
                log.warning("%s %s: %s", name, where, note)
    write_dataset(
        ds,
        snakemake.output.fit,
        title=f"Fits of e_x, Eq. ratio and Figs. 3-4 for dataset {snakemake.wildcards.dataset} (Sec. IV)",
        rule=snakemake.rule,
        inputs=data_inputs(snakemake.input),
        config=dict(snakemake.params),
    )
