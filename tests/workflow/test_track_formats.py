"""Tool files through the workflow: Tracker and Kinovea files give the long CSV's e_x end to end."""

from __future__ import annotations

import numpy as np
import pytest
import yaml


@pytest.mark.slow
def test_tool_files_run_end_to_end_with_the_long_csvs_e_x(lab_run):
    """A folder of Tracker projects (.trk, one file per impact and camera) runs through snakemake (the
    lab run's tools.yaml, conftest.lab_run) and gives the long CSV's e_x (every other format reads the
    same tracks: :func:`test_every_format_imports_the_same_tracks`).
    """
    import xarray as xr

    res = lab_run / "results"
    ref = xr.open_dataset(res / "tracked" / "fit_ex.nc")
    ref_flags = xr.open_dataset(res / "tracked" / "reduce.nc")["ingest_flag"].values
    assert np.isfinite(ref["e_x"].values).all()
    got = xr.open_dataset(res / "trk" / "fit_ex.nc")
    np.testing.assert_allclose(got["e_x"].values, ref["e_x"].values, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got["e_x_err"].values, ref["e_x_err"].values, rtol=1e-6)
    flags = xr.open_dataset(res / "trk" / "reduce.nc")["ingest_flag"].values
    np.testing.assert_array_equal(flags, ref_flags)  # the same impact excluded (tilted spin axis)
    assert (res / "trk" / "figures" / "tracks_impacts.png").is_file()
    # tool files are read by import_tracks: no tracker's quality, no clips' figures (those are import_clips')
    assert not list((res / "trk").glob("imported_quality*")) and not list((res / "trk").glob("figures/clips_*"))
    assert xr.open_dataset(res / "trk" / "imported_tracks.nc").attrs["provenance_rule"] == "import_tracks"
    found = yaml.safe_load((res / "trk" / "imported_cameras.yaml").read_text())
    assert found["cameras"]["swing"]["fps"] == pytest.approx(3000.0)
    assert found["cameras"]["spin"]["m_per_px"] == pytest.approx(0.00125, rel=1e-6)
    assert found["cameras"]["swing"]["fps_from"].startswith("12 file(s)")
