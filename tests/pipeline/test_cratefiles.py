"""Issue 37 §1: test sessions. A run's results folder is a setting; a folder's crate carries every run in
it; a folder's workbooks keep every scenario's sheet; three sessions' folders make one league table.
"""

from __future__ import annotations

import json

from ballbat.pipeline.cratefiles import folder_files


def _nc(path, note):
    """A small NetCDF file carrying the workflow's provenance mark."""
    import xarray as xr

    path.parent.mkdir(parents=True, exist_ok=True)
    attrs = {"provenance_rule": "r", "provenance_config": json.dumps({"note": note}), "note": note}
    xr.Dataset({"x": ("n", [1.0])}, attrs=attrs).to_netcdf(path, engine="netcdf4")


def test_a_session_inside_the_default_folder_is_its_own(tmp_path):
    """The files of results/2026-11-h01 (a crate of its own) are not files of results/'s crate."""
    results = tmp_path / "results"
    _nc(results / "synthetic" / "fit_ex.nc", "default")
    session = results / "2026-11-h01"
    _nc(session / "h01" / "fit_ex.nc", "session")
    assert folder_files(results) == ["2026-11-h01/h01/fit_ex.nc", "synthetic/fit_ex.nc"]  # no crate yet: a folder
    (session / "ro-crate-metadata.json").write_text("{}")
    assert folder_files(results) == ["synthetic/fit_ex.nc"]
    assert folder_files(session) == ["h01/fit_ex.nc"]
