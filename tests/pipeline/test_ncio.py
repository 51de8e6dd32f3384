"""NetCDF writing: metadata checks, provenance records, atomic and reproducible writes."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from ballbat.pipeline.ncio import MetadataError, read_dataset, write_dataset
from ballbat.pipeline.provenance import package_source_hash, sha256_file


def _ds():
    return xr.Dataset(
        {"v": ("impact", np.arange(3.0), {"units": "m s-1", "long_name": "speed"})},
        coords={"impact": ("impact", np.arange(3), {"units": "1", "long_name": "impact number"})},
    )


def test_write_records_provenance_and_is_reproducible(tmp_path):
    src = tmp_path / "in.csv"
    src.write_text("a\n1\n")
    kw = {"title": "t", "rule": "r", "inputs": {"table": str(src)}, "config": {"k": 1, "flag": True, "none": None}}
    a = write_dataset(_ds(), tmp_path / "a.nc", **kw)
    b = write_dataset(_ds(), tmp_path / "b.nc", **kw)
    assert sha256_file(a) == sha256_file(b)  # no clock in the file
    ds = read_dataset(a, require=("v",))
    assert json.loads(ds.attrs["provenance_inputs"]) == [
        {"name": "table", "path": str(src), "sha256": sha256_file(src)}
    ]
    assert json.loads(ds.attrs["provenance_config"]) == {"flag": True, "k": 1, "none": None}
    assert json.loads(ds.attrs["provenance_software"])["ballbat_source_sha256"] == package_source_hash()
    assert ds.v.attrs["units"] == "m s-1"


def test_missing_metadata_is_refused(tmp_path):
    ds = _ds()
    ds["w"] = ("impact", np.zeros(3), {"long_name": "no units"})
    with pytest.raises(MetadataError, match="w: units"):
        write_dataset(ds, tmp_path / "x.nc", title="t", rule="r", inputs={}, config={})
    assert not list(tmp_path.iterdir())  # nothing half-written


def test_failed_write_keeps_old_file(tmp_path, monkeypatch):
    path = write_dataset(_ds(), tmp_path / "a.nc", title="t", rule="r", inputs={}, config={})
    before = sha256_file(path)

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", boom)
    with pytest.raises(OSError, match="disk full"):
        write_dataset(_ds(), path, title="t2", rule="r", inputs={}, config={})
    assert sha256_file(path) == before
    assert [p.name for p in tmp_path.iterdir()] == ["a.nc"]  # no temporary left behind


def test_read_requires_variables(tmp_path):
    path = write_dataset(_ds(), tmp_path / "a.nc", title="t", rule="r", inputs={}, config={})
    with pytest.raises(MetadataError, match="missing variable\\(s\\) psi"):
        read_dataset(path, require=("psi",))


def test_results_are_readable_by_others(tmp_path):
    """Mkstemp makes private files; results get the usual 0666 less the umask."""
    import os

    umask = os.umask(0o022)
    try:
        path = write_dataset(_ds(), tmp_path / "a.nc", title="t", rule="r", inputs={}, config={})
    finally:
        os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o644
