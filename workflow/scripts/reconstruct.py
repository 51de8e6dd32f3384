"""Rule reconstruct: adapter around ballbat.stages.reconstruct.run."""

from ballbat.analysis import impact_labels
from ballbat.pipeline.ncio import read_dataset, write_job_output
from ballbat.pipeline.runlog import logged
from ballbat.properties import load_balls, load_bats
from ballbat.stages import reconstruct

with logged(snakemake.log[0], snakemake.rule) as log:
    ds = reconstruct.run(
        reconstruct.ReconstructSettings(),
        read_dataset(snakemake.input.impacts),
        balls=load_balls(snakemake.params.files["balls"]),
        bats=load_bats(snakemake.params.files["bats"]),
    )
    bad = int((ds["flag"] != 0).sum())
    log.info("%d of %d impacts not used (flagged, kept in the file)", bad, ds.sizes["impact"])
    labels = impact_labels(ds)
    for i in (ds["flag"].values != 0).nonzero()[0]:
        log.info("not used: %s: %s", labels[i], ds["flag_reason"].values[i])
    write_job_output(
        ds,
        snakemake,
        "impacts",
        f"Impacts of dataset {snakemake.wildcards.dataset} with the reconstructed geometry (Sec. III)",
    )
