"""Rules report_front and report_front_studies: adapters around ballbat.frontpage."""

import json
from pathlib import Path

from ballbat.frontpage import commit_date, front_page, studies_page, thumbnail_uri
from ballbat.pipeline.guards import warnings_summary
from ballbat.pipeline.ncio import atomic_write_text, read_dataset
from ballbat.pipeline.runlog import logged

with logged(snakemake.log[0], snakemake.rule):
    inp = snakemake.input
    if snakemake.rule == "report_front":
        kinds = snakemake.params.kinds
        datasets = {
            name: {
                "kind": kinds[name],
                "impacts": read_dataset(inp.impacts[i]),
                "fit": read_dataset(inp.fit[i]),
                "stronge": read_dataset(inp.stronge[i]),
                "fig5": inp.fig5[i],
                "thumbnail": thumbnail_uri(inp.fig5[i]),
            }
            for i, name in enumerate(kinds)
        }
        scenarios = {name: read_dataset(p) for name, p in zip(snakemake.params.scenarios, inp.scenarios, strict=True)}
        git = json.loads(next(iter(datasets.values()))["fit"].attrs["provenance_git"]) if datasets else {}
        results = Path(snakemake.output.rst).parent.parent.as_posix()  # {results}/report/front.rst
        logs = warnings_summary(results, list(kinds), ["implications"] if scenarios else [])
        league = read_dataset(inp.league[0]) if len(inp.league) else None
        date = commit_date(str(git.get("commit", "")))
        text = front_page(datasets, scenarios, logs, git, date, results, league)
    else:
        designs = snakemake.params.designs
        studies = {
            name: (read_dataset(cov), read_dataset(designs[name]) if name in designs else None)
            for name, cov in zip(snakemake.params.studies, inp.coverage, strict=True)
        }
        text = studies_page(studies)
    atomic_write_text(snakemake.output.rst, text)
