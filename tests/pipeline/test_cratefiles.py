"""The files a crate lists (ballbat.pipeline.cratefiles): a session inside the default folder is its own."""

from __future__ import annotations

from helpers import crate_netcdf as _nc

from ballbat.pipeline.cratefiles import folder_files


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
