"""Results that never outlive their inputs, whatever happens to the folder (issue 10, items 2, 4-6, 10).

The real workflow on a small measured dataset: a truncated intermediate, an input replaced by an
older copy, deleted intermediates. Each rerun ends byte-identical to a clean run. A job killed while
writing, a missing input file beside a good dataset and a measured file's warnings:
test_faults_runs.py (a module of its own, so that the two pytest-xdist processes share the reruns).
"""

from __future__ import annotations

import os

import pytest

from workflow_helpers import MAPLE_DATA as DATA
from workflow_helpers import maple_data_files as data_files
from workflow_helpers import snakemake

pytestmark = pytest.mark.slow


def test_deleted_intermediate_is_rebuilt(maple_copy):
    wd, reference = maple_copy
    (wd / "results" / "maple" / "fit_ex.nc").unlink()
    (wd / "results" / "maple" / "normalize.nc").unlink()
    snakemake(wd, "-c2", *DATA)
    assert data_files(wd) == reference


def test_truncated_intermediate_is_named_and_rebuilt(maple_copy):
    """Named by any invocation with the command that rebuilds it; nothing removed while parsing (issue 19)."""
    wd, reference = maple_copy
    path = wd / "results" / "maple" / "reconstruct.nc"
    with open(path, "r+b") as fh:
        fh.truncate(path.stat().st_size // 2)
    size = path.stat().st_size
    out = snakemake(wd, "-n")
    assert "results/maple/reconstruct.nc: truncated" in out.stderr
    assert "rebuild it with: snakemake --forcerun results/maple/reconstruct.nc" in out.stderr
    assert path.stat().st_size == size  # a dry run removes nothing
    snakemake(wd, "-c2", *DATA, "--forcerun", "results/maple/reconstruct.nc")
    assert data_files(wd) == reference


def test_input_replaced_by_an_older_copy_reruns(maple_copy):
    """Cp -p / tar / rsync -a keep an old timestamp: the rerun must follow the content."""
    wd, reference = maple_copy
    src = wd / "config" / "examples" / "maple_impacts.csv"
    original = src.read_bytes()
    old = os.stat(src).st_mtime - 10 * 86400
    try:
        lines = original.decode().splitlines()
        src.write_text("\n".join(lines[:-1]) + "\n")  # one impact fewer
        os.utime(src, (old, old))
        snakemake(wd, "-c2", *DATA)
        changed = data_files(wd)
        assert changed["ingest.nc"] != reference["ingest.nc"]
        import xarray as xr

        with xr.open_dataset(wd / "results" / "maple" / "ingest.nc") as ds:
            assert ds.sizes["impact"] == len(lines) - 2
    finally:
        src.write_bytes(original)
        os.utime(src, (old, old))
    snakemake(wd, "-c2", *DATA)
    assert data_files(wd) == reference
