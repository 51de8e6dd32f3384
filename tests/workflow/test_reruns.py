"""End to end: a finished run is a no-op, and made again it is byte-identical (the suite's lab run,
conftest.lab_run, in a copy). A module of its own (from workflow/test_outputs.py) so that ``make test``'s
two pytest-xdist processes, a module each, run it beside workflow/test_outputs.py's tests.
"""

from __future__ import annotations

import time

import pytest

from ballbat.pipeline.provenance import sha256_file
from workflow_helpers import copy_run, planned_jobs, snakemake

pytestmark = pytest.mark.slow


def test_rerun_is_noop_and_byte_identical(lab_run, tmp_path):
    """Nothing to do in a finished run; small's chain made again (its data, workbook, a figure of each
    kind, the paper scenario): the same, byte for byte.
    """
    wd = copy_run(lab_run, tmp_path / "wd")
    assert planned_jobs(wd) == {}
    res = wd / "results"
    files = [*sorted((res / "small").glob("*.nc")), res / "small" / "results.xlsx"]  # workbooks: fixed metadata
    figures = ["fig3", "fig9a", "tracks_impacts"]  # figures: no timestamps (scatter and lines, curves, QA)
    files += [res / "small" / "figures" / f"{name}.png" for name in figures]
    files += [res / "implications" / "paper.nc", res / "implications" / "figures" / "paper_fig11a.png"]
    assert len(files) == 7 + 1 + 3 + 2
    before = {p: sha256_file(p) for p in files}
    started = time.time()
    snakemake(wd, "-c2", "--forcerun", "simulate", "--", *(str(p.relative_to(wd)) for p in files))
    assert all(p.stat().st_mtime >= started - 1 for p in files)  # every one made again
    after = {p: sha256_file(p) for p in files}
    assert before == after
