"""The files a crate lists (ballbat.pipeline.cratefiles): a session inside the default folder is its own."""

from __future__ import annotations

from helpers import crate_folder as _folder
from helpers import crate_graph as _graph
from helpers import crate_netcdf as _nc

from ballbat.pipeline import crate as crate_mod
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


def test_validator_names_the_check_and_the_file(tmp_path, capsys):
    """A crate listing a deleted file and a changed one fails, and tests/validate_crate.py says which check
    failed on which file (its ``--files`` checks: the crate's own, without roc-validator's profile).
    """
    from validate_crate import main

    from ballbat.pipeline.cratefiles import crate_file_problems

    results, job = _folder(tmp_path)
    crate_mod.write_run_crate(results, [job], config={}, configfiles=[], workdir=tmp_path)
    (results / "logs" / "a.log").unlink()
    listed = _graph(results)["a.nc"]
    with open(results / "a.nc", "ab") as fh:
        fh.write(b"four")
    (results / "new.txt").write_text("x")
    size = (results / "a.nc").stat().st_size
    assert crate_file_problems(results) == [
        f"sha256 differs: a.nc: the crate says {listed['sha256'][:12]}..., the file has another",
        f"size differs: a.nc: the crate says {listed['contentSize']} bytes, the file has {size}",
        "listed file missing: logs/a.log is in the crate but not in the folder",
        "file not listed: new.txt is in the folder but not in the crate",
    ]
    assert main([str(results), "--files"]) == 1  # roc-validator's run: test_crate_validates_offline
    err = capsys.readouterr().err
    assert "check failed: listed file missing: logs/a.log" in err and "the crate fails 4 check(s)" in err
