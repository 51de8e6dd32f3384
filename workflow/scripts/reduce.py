"""Rule reduce: adapter around ballbat.stages.reduce.run."""

import yaml

from ballbat.pipeline.ncio import write_job_output
from ballbat.pipeline.runlog import log_exclusions, logged
from ballbat.properties import InputError, load_balls, load_bats
from ballbat.stages import reduce
from ballbat.tracks.data import name_found_settings, with_found_settings
from ballbat.tracks.io import load_tracks

with logged(snakemake.log[0], snakemake.rule) as log:
    inp = snakemake.input
    block = snakemake.params.settings
    if "cameras" in inp.keys():  # a folder of tool files: the camera settings found in them
        block = with_found_settings(block, yaml.safe_load(open(inp.cameras)))
    # a file the config names but that is missing is no input (common.smk: existing); reading it
    # by its configured name fails this job alone, with a message naming the file
    named = snakemake.params.files
    tracks_path = inp.get("tracks") or named["tracks"]
    balls, bats = load_balls(inp.get("balls") or named["balls"]), load_bats(inp.get("bats") or named["bats"])
    settings = reduce.ReduceSettings.from_config(
        block, snakemake.params.where, systematics=True
    )  # checked before the files are read
    tracks = load_tracks(tracks_path, inp.get("impacts") or named.get("tracks_impacts"), balls, bats)
    try:
        ds = reduce.run(settings, tracks, balls, bats, source_file=tracks_path)
    except InputError as exc:  # a setting the files gave is named as read from them
        found = yaml.safe_load(open(inp.cameras)) if "cameras" in inp.keys() else {}
        raise InputError(name_found_settings(exc.problems, found)) from None
    for line in ds.attrs["reduce_checks"].splitlines():
        log.info("cross-check: %s", line)
    for text in ds.attrs["reduce_warnings"].splitlines():
        log.warning(text)
    log_exclusions(log, reduce.excluded_listing(ds), ds.sizes["impact"])
    write_job_output(
        ds,
        snakemake,
        "impacts",
        f"Impacts of dataset {snakemake.wildcards.dataset} reduced from raw camera tracks (Sec. II)",
    )
