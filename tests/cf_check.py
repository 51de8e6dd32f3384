"""Run the IOOS compliance-checker with its dataset queries answered once per dataset.

``python tests/cf_check.py ARGS`` is ``compliance-checker ARGS`` (its own ``cchecker.main``), with
one change: the queries of :mod:`compliance_checker.cf.util` that take only the dataset
(``get_axis_variables(nc)``, ``get_time_variables(nc)``, ...) remember their answer for that
open dataset. The checker asks them again for every variable it checks, and each answer reads
every attribute of every variable, so a file's check grew as the square of its variables:
17 s for a file of 108 variables, 2-3 s with the answers kept. The answers are the same (each
query only reads the file, which the checker opens read-only) and each caller gets its own copy
of a list; tests/workflow/test_outputs.py compares the report with the unpatched checker's once
(:func:`workflow_helpers.assert_cf` runs this script).
"""

from __future__ import annotations

import copy
import functools
import sys
from pathlib import Path

#: Queries of compliance_checker.cf.util that depend on the dataset alone.
DATASET_QUERIES = (
    "get_coordinate_variables",
    "get_auxiliary_coordinate_variables",
    "get_cell_boundary_map",
    "get_cell_boundary_variables",
    "get_bounds_variables",
    "get_geophysical_variables",
    "get_z_variables",
    "get_latitude_variables",
    "get_true_latitude_variables",
    "get_longitude_variables",
    "get_true_longitude_variables",
    "get_time_variables",
    "get_axis_variables",
    "get_flag_variables",
    "get_grid_mapping_variables",
)


def _remembered(query):
    answers: dict[int, tuple[object, object]] = {}

    @functools.wraps(query)
    def ask(nc):
        key = id(nc)
        if key not in answers or answers[key][0] is not nc:  # the object itself is kept: an id is not reused
            answers[key] = (nc, query(nc))
        return copy.copy(answers[key][1])

    return ask


def remember_dataset_queries() -> None:
    """Replace each of :data:`DATASET_QUERIES` in compliance_checker.cf.util with its remembering form."""
    from compliance_checker.cf import util

    for name in DATASET_QUERIES:
        setattr(util, name, _remembered(getattr(util, name)))


if __name__ == "__main__":
    remember_dataset_queries()
    sys.path.insert(0, str(Path(sys.executable).parent))  # the checker installs its cchecker.py beside python
    from cchecker import main

    sys.argv[0] = "compliance-checker"
    sys.exit(main())
