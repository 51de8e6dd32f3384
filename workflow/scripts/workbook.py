"""Rules workbook and implications_workbook: adapters around ballbat.workbook."""

from pathlib import Path

from ballbat.compare import read_csv
from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.runlog import logged
from ballbat.workbook import dataset_workbook, implications_workbook

with logged(snakemake.log[0], snakemake.rule):
    if snakemake.rule == "workbook":
        dataset_workbook(
            snakemake.output.xlsx,
            impacts=read_dataset(snakemake.input.impacts),
            fit=read_dataset(snakemake.input.fit),
            stronge=read_dataset(snakemake.input.stronge),
            comparison=read_csv(snakemake.input.comparison),
        )
    else:
        implications_workbook(snakemake.output.xlsx, {Path(p).stem: read_dataset(p) for p in snakemake.input.scenarios})
