"""Rules workbook and implications_workbook: adapters around ballbat.workbook."""

from pathlib import Path

from ballbat.compare import read_csv
from ballbat.pipeline.ncio import read_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import logged
from ballbat.workbook import custom_properties, dataset_workbook, implications_workbook

with logged(snakemake.log[0], snakemake.rule):
    # the workbook's provenance in its custom document properties: each input file with its sha256
    files = [f for v in data_inputs(snakemake.input).values() for f in ([v] if isinstance(v, str) else v)]
    inputs = {Path(f).name: f for f in files}
    properties = {"rule": snakemake.rule, **custom_properties(inputs)}
    if snakemake.rule == "workbook":
        dataset_workbook(
            snakemake.output.xlsx,
            impacts=read_dataset(snakemake.input.impacts),
            fit=read_dataset(snakemake.input.fit),
            stronge=read_dataset(snakemake.input.stronge),
            comparison=read_csv(snakemake.input.comparison),
            properties=properties,
        )
    else:
        implications_workbook(
            snakemake.output.xlsx,
            {Path(p).stem: read_dataset(p) for p in snakemake.input.scenarios},
            properties=properties,
        )
