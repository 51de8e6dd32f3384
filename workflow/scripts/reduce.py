"""Rule reduce: adapter around ballbat.tracks.stage.reduce_stage."""

import yaml

from ballbat.pipeline.ncio import write_dataset
from ballbat.pipeline.provenance import data_inputs
from ballbat.pipeline.runlog import log_exclusions, logged
from ballbat.tracks.data import with_found_settings
from ballbat.tracks.stage import excluded_listing, reduce_stage

with logged(snakemake.log[0], snakemake.rule) as log:
    inp = snakemake.input
    settings = snakemake.params.settings
    if "cameras" in inp.keys():  # a folder of tool files: the camera settings found in them
        settings = with_found_settings(settings, yaml.safe_load(open(inp.cameras)))
    # a file the config names but that is missing is no input (common.smk: existing); reading it
    # by its configured name fails this job alone, with a message naming the file
    named = snakemake.config["datasets"][snakemake.wildcards.dataset]
    tables = {k: named.get(k, snakemake.config["tables"][k]) for k in ("balls", "bats")}
    ds = reduce_stage(
        inp.get("tracks") or named["tracks"]["file"],
        inp.get("impacts") or named.get("tracks", {}).get("impacts"),
        settings,
        inp.get("balls") or tables["balls"],
        inp.get("bats") or tables["bats"],
        where=snakemake.params.where,
    )
    for line in ds.attrs["reduce_checks"].splitlines():
        log.info("cross-check: %s", line)
    for text in ds.attrs["reduce_warnings"].splitlines():
        log.warning(text)
    log_exclusions(log, excluded_listing(ds), ds.sizes["impact"])
    write_dataset(
        ds,
        snakemake.output.impacts,
        title=f"Impacts of dataset {snakemake.wildcards.dataset} reduced from raw camera tracks (Sec. II)",
        rule=snakemake.rule,
        inputs=data_inputs(inp),
        config=dict(snakemake.params),
    )
