"""What the fork server of :mod:`forked` loads once, before it forks each run.

Snakemake's own modules and the third-party libraries its start imports (the report's
libraries, smart_open, jsonschema; pandas, which it imports for the parameters' records unless
the workflow spares it, ballbat.pipeline.params_record), and its plugin registries, collected
once by building the command line's parser: about 1.3 s of every run's start (profiled with
``python -X importtime`` and cProfile on ``snakemake -n``).
Then the libraries the ``ballbat`` command imports (xarray and netCDF4, scipy's optimize and
stats, lmfit, openpyxl, yaml): 1-2.5 s of each command's start. And matplotlib's pyplot on
its Agg backend (as :mod:`ballbat.plotting` sets it), about 0.8 s of each figure job's start.
Nothing of ballbat is loaded: each run imports it afresh (from ``workdir/src`` when the run
has its own copy), as ``python -m snakemake`` does.
"""

import jsonschema  # noqa: F401
import lmfit  # noqa: F401
import matplotlib
import netCDF4  # noqa: F401
import openpyxl  # noqa: F401
import pandas  # noqa: F401
import scipy.optimize
import scipy.stats  # noqa: F401
import smart_open  # noqa: F401
import snakemake.api
import snakemake.dag
import snakemake.persistence
import snakemake.report
import snakemake.workflow  # noqa: F401
import xarray  # noqa: F401
import yaml  # noqa: F401
from snakemake.cli import get_argument_parser

matplotlib.use("Agg")
import matplotlib.pyplot

get_argument_parser()  # fills the plugin registries (singletons), which every start reads
