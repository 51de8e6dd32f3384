"""Rule compare: adapter around ballbat.compare."""

from ballbat.compare import stronge_rows, write_comparison
from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import job_provenance, write_sidecar
from ballbat.pipeline.runlog import logged

with logged(snakemake.log[0], snakemake.rule):
    write_comparison(
        fit=snakemake.input.fit,
        impacts=snakemake.input.impacts,
        csv_path=snakemake.output.csv,
        md_path=snakemake.output.md,
        title=f"Dataset {snakemake.wildcards.dataset}: the paper's numbers beside ours",
        extra_rows=stronge_rows(read_dataset(snakemake.input.stronge)),
    )
    # the tables' provenance beside them (a comment line is not CSV: docs/provenance.md)
    write_sidecar(snakemake.output.prov, [snakemake.output.csv, snakemake.output.md], *job_provenance(snakemake))
