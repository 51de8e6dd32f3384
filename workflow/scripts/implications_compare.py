"""Rule implications_compare: adapter around ballbat.compare for the paper scenario."""

from ballbat.compare import write_table
from ballbat.implications import comparison_rows
from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import job_provenance, write_sidecar
from ballbat.pipeline.runlog import logged
from ballbat.published import PUBLISHED_IMPLICATIONS

with logged(snakemake.log[0], snakemake.rule):
    write_table(
        comparison_rows(read_dataset(snakemake.input.scenario)),
        csv_path=snakemake.output.csv,
        md_path=snakemake.output.md,
        title="Sec. V.B, scenario paper: the paper's statements beside ours",
        published=PUBLISHED_IMPLICATIONS,
    )
    # the tables' provenance beside them (a comment line is not CSV: docs/provenance.md)
    write_sidecar(snakemake.output.prov, [snakemake.output.csv, snakemake.output.md], *job_provenance(snakemake))
