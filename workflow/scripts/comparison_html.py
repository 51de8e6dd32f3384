"""Rule comparison_html: adapter around ballbat.reporting.comparison_html (table for the report)."""

from pathlib import Path

from ballbat.pipeline.runlog import logged
from ballbat.reporting import comparison_html

with logged(snakemake.log[0], snakemake.rule):
    comparison_html(
        snakemake.input.csv,
        snakemake.output.html,
        title=f"{Path(snakemake.input.csv).parent.as_posix()}: the paper's numbers beside ours",
    )
