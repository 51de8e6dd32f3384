"""A folder of clips through the workflow (docs/video.md, "In the workflow"): tracked on import, then reduced."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from video_clips import LAB_CAMERAS, LAB_RIG, LAB_TRUTH

from ballbat.units import DEGREE, MPH, RPM
from workflow_helpers import make_workdir, snakemake, write_config


@pytest.mark.slow
def test_a_folder_of_clips_is_tracked_and_reduced_to_its_impacts(tmp_path, lab_clips):
    import shutil

    import xarray as xr

    wd = make_workdir(tmp_path)
    shutil.copytree(lab_clips[0], wd / "lab" / "clips")
    block = {
        "dir": "lab/clips",
        "format": "video",
        "impacts": "lab/clips/impacts.csv",
        "cameras": {c: {"m_per_px": v["m_per_px"], "mirror": False} for c, v in LAB_CAMERAS.items()},
        "rig": LAB_RIG,
        "video": {"dot_radius_mm": 4.0, "marker_radius_mm": 6.0},
    }
    write_config(wd, lambda cfg: cfg["datasets"].update(vid={"tracks": block}))
    snakemake(wd, "-c2", "--", "results/vid/reduce.nc")
    found = yaml.safe_load((wd / "results" / "vid" / "imported_cameras.yaml").read_text())
    assert found["files"] == 6 and found["cameras"]["swing"]["fps"] == 3000.0  # the frame rate from the clips
    red = xr.open_dataset(wd / "results" / "vid" / "reduce.nc")
    assert list(red["impact_id"].values) == ["W1", "W2", "W3"]
    # the clips' true impacts, within a few of the reduction's own standard errors (SI units)
    unit = {"v_bat": MPH, "v_ball": MPH, "theta": DEGREE, "omega": RPM}
    for name, u in unit.items():
        got, err = red[name].values, red[f"{name}_err"].values
        assert np.all(np.abs(got - LAB_TRUTH[name] * u) < 4 * err), (name, got / u, err / u)
