"""What the fork server of :func:`workflow_helpers.snakemake` loads once, before it forks each run.

Snakemake's own modules and the third-party libraries its start imports (pandas for the
parameters' records, the report's libraries, smart_open, jsonschema), and its plugin
registries, collected once by building the command line's parser: about 1.3 s of every
run's start (profiled with ``python -X importtime`` and cProfile on ``snakemake -n``).
Nothing of ballbat is loaded: each run imports it afresh (from ``workdir/src`` when the run
has its own copy), as ``python -m snakemake`` does.
"""

import jsonschema  # noqa: F401
import pandas  # noqa: F401
import smart_open  # noqa: F401
import snakemake.api
import snakemake.dag
import snakemake.persistence
import snakemake.report
import snakemake.workflow  # noqa: F401
from snakemake.cli import get_argument_parser

get_argument_parser()  # fills the plugin registries (singletons), which every start reads
